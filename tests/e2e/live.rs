//! `sim --live` (feature `live`): a WebSocket client that speaks Foxglove's protocol
//! (<https://github.com/foxglove/ws-protocol/blob/main/docs/spec.md>: `advertise` and
//! `subscribe` as JSON text frames, message data as binary frames of opcode 1, subscription id
//! u32 LE, timestamp u64 LE, payload) receives every channel of the recording, with the same
//! topics and schemas, every message of it, and `/robot_description`; and a recording made with
//! `--live` is byte-identical to one made without. Without the feature, `--live` is an error
//! that names it.

#[cfg(not(feature = "live"))]
#[test]
fn without_the_feature_live_is_an_error_naming_it() {
    let dir = tempfile::tempdir().unwrap();
    let out = super::run_sim(&["run", "paper", "--run", "two-elbow", "--duration", "0.01", "--live", "-o"].map(std::ffi::OsStr::new).into_iter().chain([dir.path().as_os_str()]).collect::<Vec<_>>());
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("feature `live`") && err.contains("--features live"), "{err}");
    assert!(std::fs::read_dir(dir.path()).unwrap().next().is_none(), "nothing is run");
}

#[cfg(feature = "live")]
mod with_the_feature {
    use std::collections::BTreeMap;
    use std::io::{BufRead, BufReader};
    use std::path::{Path, PathBuf};
    use std::process::{Child, Command, Stdio};
    use std::sync::mpsc::{self, Receiver};
    use std::time::{Duration, Instant};

    use tungstenite::client::IntoClientRequest;
    use tungstenite::stream::MaybeTlsStream;
    use tungstenite::Message;

    /// The scene of both tests: a run with unilateral contacts (so `/contacts` too, and
    /// `/contact_events` if an event happens), short.
    const SCENE: [&str; 6] = ["run", "paper-unilateral", "--run", "two-elbow-unilateral", "--duration", "0.3"];
    const FILE: &str = "paper-unilateral-two-elbow-unilateral.mcap";

    /// A guard against a hung server, not a measured time: far beyond what the run takes.
    const GIVE_UP: Duration = Duration::from_secs(300);

    /// `sim` with `args` and `-o out`, its stderr lines sent on the channel as they come.
    fn spawn_sim(args: &[&str], out: &Path) -> (Child, Receiver<String>) {
        let mut child = Command::new(env!("CARGO_BIN_EXE_sim"))
            .args(args)
            .arg("-o")
            .arg(out)
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .expect("sim starts");
        let stderr = child.stderr.take().unwrap();
        let (tx, rx) = mpsc::channel();
        std::thread::spawn(move || {
            for line in BufReader::new(stderr).lines().map_while(Result::ok) {
                if tx.send(line).is_err() {
                    break;
                }
            }
        });
        (child, rx)
    }

    /// The next stderr line that contains `what`, and the lines before it.
    fn wait_for_line(rx: &Receiver<String>, what: &str, seen: &mut Vec<String>) -> String {
        loop {
            match rx.recv_timeout(GIVE_UP) {
                Ok(line) if line.contains(what) => return line,
                Ok(line) => seen.push(line),
                Err(e) => panic!("no line with {what:?} from sim ({e}); stderr so far:\n{}", seen.join("\n")),
            }
        }
    }

    /// The port of "ws://127.0.0.1:PORT ..." printed by `sim --live`.
    fn port_of(line: &str) -> u16 {
        let rest = &line[line.find("ws://127.0.0.1:").expect("an address") + "ws://127.0.0.1:".len()..];
        rest.split(|c: char| !c.is_ascii_digit()).next().unwrap().parse().expect("a port")
    }

    /// A channel as advertised.
    #[derive(Debug, Clone)]
    struct Advertised {
        topic: String,
        encoding: String,
        schema_name: String,
        schema_encoding: String,
    }

    #[derive(Default)]
    struct Received {
        channels: BTreeMap<u64, Advertised>,
        /// subscription id → channel id
        subscriptions: BTreeMap<u32, u64>,
        /// per topic: (timestamp, payload length) in arrival order
        messages: BTreeMap<String, Vec<(u64, usize)>>,
        robot_description: Vec<Vec<u8>>,
        server_name: Option<String>,
        /// Subscriptions sent again after the server refused them as unknown (see `frame`).
        resubscribed: usize,
    }

    impl Received {
        /// Handles one frame; returns the subscribe request to send, if any.
        fn frame(&mut self, msg: Message) -> Option<String> {
            match msg {
                Message::Text(text) => {
                    let v: serde_json::Value = serde_json::from_str(text.as_str()).expect("text frames are JSON");
                    match v["op"].as_str() {
                        Some("serverInfo") => self.server_name = v["name"].as_str().map(str::to_string),
                        // The `foxglove` crate (0.30.3, `ConnectedClient::advertise_channels`)
                        // sends an advertisement before it enters the channel in the client's
                        // map; a client that answers before the server's thread gets there is
                        // refused with this status (level 2) and its subscription dropped. A
                        // channel advertised mid-run (`/contact_events`, at the first event)
                        // met it on a loaded machine. Our advertisement stands, so the client
                        // subscribes again, as a robust client would; anything else refused fails.
                        Some("status") if v["level"].as_u64() == Some(2) => {
                            let message = v["message"].as_str().unwrap_or_default();
                            let channel: u64 = message.strip_prefix("Unknown channel ID: ").and_then(|n| n.trim().parse().ok()).unwrap_or_else(|| panic!("the server refused: {v}"));
                            let sub = *self.subscriptions.iter().find(|(_, c)| **c == channel).unwrap_or_else(|| panic!("refused a channel never subscribed: {v}")).0;
                            self.resubscribed += 1;
                            eprintln!("live test: {message}; subscribing again");
                            assert!(self.resubscribed <= 100, "a subscription refused 100 times: {v}");
                            std::thread::sleep(std::time::Duration::from_millis(10));
                            return Some(serde_json::json!({ "op": "subscribe", "subscriptions": [{ "id": sub, "channelId": channel }] }).to_string());
                        }
                        Some("advertise") => {
                            let mut subs = Vec::new();
                            for c in v["channels"].as_array().expect("channels") {
                                let id = c["id"].as_u64().expect("a channel id");
                                let s = |k: &str| c[k].as_str().unwrap_or_default().to_string();
                                let ad = Advertised { topic: s("topic"), encoding: s("encoding"), schema_name: s("schemaName"), schema_encoding: s("schemaEncoding") };
                                self.channels.insert(id, ad);
                                let sub = self.subscriptions.len() as u32 + 1;
                                self.subscriptions.insert(sub, id);
                                subs.push(serde_json::json!({ "id": sub, "channelId": id }));
                            }
                            return Some(serde_json::json!({ "op": "subscribe", "subscriptions": subs }).to_string());
                        }
                        _ => {}
                    }
                }
                Message::Binary(b) => {
                    assert_eq!(b[0], 1, "only message data (opcode 1) is expected");
                    assert!(b.len() >= 13, "a message data frame has a 13-byte header");
                    let sub = u32::from_le_bytes(b[1..5].try_into().unwrap());
                    let t = u64::from_le_bytes(b[5..13].try_into().unwrap());
                    let channel = self.subscriptions.get(&sub).expect("data for a subscription of ours");
                    let topic = self.channels[channel].topic.clone();
                    if topic == schemas::topics::ROBOT_DESCRIPTION {
                        self.robot_description.push(b[13..].to_vec());
                    }
                    self.messages.entry(topic).or_default().push((t, b.len() - 13));
                }
                _ => {}
            }
            None
        }

        fn count(&self, topic: &str) -> usize {
            self.messages.get(topic).map_or(0, Vec::len)
        }
    }

    /// A client waiting before the run (`--wait`, `--pace fast`, any port) subscribes to every
    /// channel as it is advertised and receives every channel of the recording with its topic,
    /// message encoding, schema name and encoding, every message (counts equal, timestamps the
    /// log times, in order per channel) and the URDF; the file is the one a run without
    /// `--live` writes.
    #[test]
    fn a_client_receives_every_channel_and_message_of_the_recording() {
        let dir = tempfile::tempdir().unwrap();
        let (live_dir, plain_dir) = (dir.path().join("live"), dir.path().join("plain"));
        let mut args = SCENE.to_vec();
        args.extend(["--live", "--live-port", "0", "--wait", "--pace", "fast"]);
        let (mut child, lines) = spawn_sim(&args, &live_dir);
        let mut stderr = Vec::new();
        let port = port_of(&wait_for_line(&lines, "ws://", &mut stderr));

        let mut request = format!("ws://127.0.0.1:{port}").into_client_request().unwrap();
        request.headers_mut().insert("Sec-WebSocket-Protocol", "foxglove.sdk.v1".parse().unwrap());
        let (mut socket, response) = tungstenite::connect(request).expect("the live server accepts a Foxglove client");
        assert_eq!(response.headers().get("sec-websocket-protocol").and_then(|v| v.to_str().ok()), Some("foxglove.sdk.v1"));
        if let MaybeTlsStream::Plain(s) = socket.get_mut() {
            s.set_read_timeout(Some(Duration::from_millis(200))).unwrap();
        }

        let mut got = Received::default();
        let mut expected: Option<(PathBuf, schemas::Recording)> = None;
        let started = Instant::now();
        loop {
            assert!(started.elapsed() < GIVE_UP, "gave up; received {:?}; stderr:\n{}", got.messages.keys(), stderr.join("\n"));
            match socket.read() {
                Ok(msg) => {
                    if let Some(subscribe) = got.frame(msg) {
                        socket.send(Message::text(subscribe)).unwrap();
                    }
                }
                Err(tungstenite::Error::Io(e)) if matches!(e.kind(), std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut) => {}
                Err(e) => panic!("the connection failed: {e}; stderr:\n{}", stderr.join("\n")),
            }
            while let Ok(line) = lines.try_recv() {
                if line.starts_with("wrote ") {
                    let path = live_dir.join(FILE);
                    expected = Some((path.clone(), schemas::read_recording(&path).expect("the recording reads")));
                }
                stderr.push(line);
            }
            if let Some((_, rec)) = &expected {
                if rec.channels.iter().all(|c| got.count(&c.topic) >= c.message_count) {
                    break;
                }
            }
        }
        socket.close(None).unwrap();
        // (the server answers the close; sim then sees no client and exits)
        let _ = socket.read();
        let status = child.wait().unwrap();
        stderr.extend(lines.try_iter());
        assert!(status.success(), "sim --live failed: {status}; stderr:\n{}", stderr.join("\n"));

        let (path, rec) = expected.unwrap();
        assert_eq!(got.server_name.as_deref(), Some("elbow-sim"));
        // every channel of the recording, advertised as in the file, and nothing else
        let advertised: BTreeMap<&str, &Advertised> = got.channels.values().map(|a| (a.topic.as_str(), a)).collect();
        let in_file: Vec<&str> = rec.channels.iter().map(|c| c.topic.as_str()).collect();
        assert_eq!(advertised.keys().copied().collect::<Vec<_>>(), { let mut t = in_file.clone(); t.sort(); t }, "topics");
        for topic in [schemas::topics::CONTACTS, schemas::topics::TF, schemas::topics::ROBOT_DESCRIPTION] {
            assert!(in_file.contains(&topic), "the scene records {topic}");
        }
        for c in &rec.channels {
            let a = advertised[c.topic.as_str()];
            assert_eq!((&a.encoding, &a.schema_name, &a.schema_encoding), (&c.message_encoding, &c.schema_name, &c.schema_encoding), "{}", c.topic);
            // every message, once, in log-time order, stamped with its log time
            let msgs = got.messages.get(&c.topic).map_or(&[][..], Vec::as_slice);
            assert_eq!(msgs.len(), c.message_count, "messages on {}", c.topic);
            assert!(msgs.windows(2).all(|w| w[0].0 <= w[1].0), "{} in log-time order", c.topic);
            assert!(msgs.iter().all(|(_, n)| *n > 0), "{}: no empty payload", c.topic);
        }
        let times = |topic: &str| got.messages[topic].iter().map(|m| m.0).collect::<Vec<_>>();
        let hand_times: Vec<u64> = rec.messages(schemas::topics::HAND).expect("/hand").iter().map(|m| m.0).collect();
        assert_eq!(times(schemas::topics::HAND), hand_times, "timestamps are the recording's log times");
        assert_eq!(got.robot_description.len(), 1);
        let urdf = &got.robot_description[0];
        assert!(urdf.windows(7).any(|w| w == b"<robot "), "/robot_description carries the URDF");

        // the same run without --live writes the same bytes
        let out = super::super::run_sim(&[SCENE.as_slice(), &["-q", "-o", plain_dir.to_str().unwrap()]].concat());
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        assert!(std::fs::read(&path).unwrap() == std::fs::read(plain_dir.join(FILE)).unwrap(), "--live changed the recording");
    }

    /// Paced to real time (here 20x slower: 6 s for the 0.3 s run), with no client, a run writes the bytes of an unpaced run
    /// without `--live`, and a client that connects after the run started still gets the URDF
    /// (latched) once it subscribes.
    ///
    /// The client must subscribe while the run lasts. On a loaded machine (CI runs this beside
    /// the whole suite on two cores) the 6 s can pass before the server has handled the
    /// subscription: a run that ends before any message reached the client says nothing about
    /// latching, so it is tried again 5x slower (at most twice). A client that received other
    /// topics' messages (its subscription was live) and never the URDF fails the test.
    #[test]
    fn pacing_changes_no_byte_and_a_late_client_still_gets_the_urdf() {
        let dir = tempfile::tempdir().unwrap();
        let plain_dir = dir.path().join("plain");
        let mut tries = Vec::new();
        let (got, live_dir) = loop {
            let speed = 0.05 * 0.2_f64.powi(tries.len() as i32);
            let live_dir = dir.path().join(format!("live-{}", tries.len()));
            match late_client(&live_dir, speed) {
                Ok(got) => break (got, live_dir),
                Err(why) if tries.len() < 2 => tries.push(why),
                Err(why) => panic!("the run ended before a late client's subscription took effect, three times (speeds 0.05, 0.01, 0.002): {tries:?}; {why}"),
            }
        };
        let urdf = &got.robot_description[0];
        assert!(urdf.windows(7).any(|w| w == b"<robot "), "/robot_description carries the URDF");

        let out = super::super::run_sim(&[SCENE.as_slice(), &["-q", "-o", plain_dir.to_str().unwrap()]].concat());
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        assert!(std::fs::read(live_dir.join(FILE)).unwrap() == std::fs::read(plain_dir.join(FILE)).unwrap(), "--live --pace realtime changed the recording");
    }

    /// One paced run (`--speed speed`) and a client that connects once it streams: what the
    /// client received once the URDF came (and the run then ended with exit 0), or why nothing
    /// can be said (the run ended before any message reached the client). Panics when the
    /// client's subscription was live (it received messages) and the URDF never came.
    fn late_client(live_dir: &Path, speed: f64) -> Result<Received, String> {
        let mut args = SCENE.to_vec();
        let speed_arg = format!("{speed}");
        args.extend(["--live", "--live-port", "0", "--speed", &speed_arg]);
        let (mut child, lines) = spawn_sim(&args, live_dir);
        let mut stderr = Vec::new();
        let port = port_of(&wait_for_line(&lines, "ws://", &mut stderr));
        // connect once the run streams (its channels are advertised on connection)
        wait_for_line(&lines, "streaming", &mut stderr);
        let mut request = format!("ws://127.0.0.1:{port}").into_client_request().unwrap();
        request.headers_mut().insert("Sec-WebSocket-Protocol", "foxglove.sdk.v1".parse().unwrap());
        let (mut socket, _) = tungstenite::connect(request).expect("the live server accepts a Foxglove client");
        if let MaybeTlsStream::Plain(s) = socket.get_mut() {
            s.set_read_timeout(Some(Duration::from_millis(200))).unwrap();
        }
        let mut got = Received::default();
        let started = Instant::now();
        while got.robot_description.is_empty() {
            assert!(started.elapsed() < GIVE_UP, "no /robot_description; stderr:\n{}", stderr.join("\n"));
            match socket.read() {
                Ok(msg) => {
                    if let Some(subscribe) = got.frame(msg) {
                        socket.send(Message::text(subscribe)).unwrap();
                    }
                }
                Err(tungstenite::Error::Io(e)) if matches!(e.kind(), std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut) => {}
                Err(e) => {
                    let status = child.wait().unwrap();
                    stderr.extend(lines.try_iter());
                    let counts: Vec<(String, usize)> = got.messages.iter().map(|(t, m)| (t.clone(), m.len())).collect();
                    let why = format!(
                        "speed {speed}: the connection ended after {:.1} s ({e}), sim {status}; advertised {} channels, received {counts:?}; stderr:\n{}",
                        started.elapsed().as_secs_f64(),
                        got.channels.len(),
                        stderr.join("\n")
                    );
                    // messages came, so the subscription was live while the run lasted: the URDF was lost
                    assert!(got.messages.is_empty(), "a subscribed client never got the latched URDF: {why}");
                    return Err(why);
                }
            }
        }
        drop(socket);
        let status = child.wait().unwrap();
        stderr.extend(lines.try_iter());
        assert!(status.success(), "sim --live failed: {status}; stderr:\n{}", stderr.join("\n"));
        Ok(got)
    }
}
