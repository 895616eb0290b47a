//! The live server (feature `live`): the `foxglove` crate's `WebSocketServer` on a context of
//! its own, a [`Hub`] of the current run's channels shared by the writer's mirror
//! ([`LiveMirror`], on the writer's thread) and the server's subscription callbacks
//! ([`HubListener`], on the server's threads). See the parent module for what is streamed when.
//!
//! Messages go to each subscribed client by its sink id, chosen under the hub's lock: a client
//! gets the kept messages (latched, or all until the first subscription with `--wait`) before
//! any newer one, each once. Lock order: hub, then the SDK's own (never the reverse: channels
//! are closed outside the hub's lock, since closing calls `on_unsubscribe`).

use std::collections::{BTreeMap, HashMap, VecDeque};
use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, MutexGuard, PoisonError};
use std::time::{Duration, Instant};

use foxglove::websocket::{ChannelView, Client, ServerListener, Status};
use foxglove::{ChannelBuilder, ChannelId, Context, PartialMetadata, RawChannel, Schema, SinkId, WebSocketServer, WebSocketServerHandle};

use super::{LiveArgs, Pace};

/// Bytes of messages kept per channel until its first subscription (`--wait`); beyond, the
/// oldest are dropped, counted, and reported when the command ends (exit status 1). A paper
/// run's largest channel (`/tf`, 5 s at 1 kHz) is about 6 MB.
pub const KEPT_BYTES: usize = 64 << 20;

/// Messages queued per client by the server before it drops the oldest (the crate's default
/// is 1024): a fast run writes thousands of messages in a burst.
const BACKLOG_FAST: usize = 1 << 17;

/// Times the `foxglove` crate said a client's queue was full (it then drops that client's
/// oldest queued messages): see [`OutboxWatch`].
static OUTBOX_FULL: AtomicU64 = AtomicU64::new(0);

/// The `foxglove` crate (0.30, `websocket/connected_client/send_lossy.rs`) drops the oldest
/// messages queued for a client that falls behind (its queue holds `message_backlog_size`
/// messages) and has no count or callback for it in its API: it only logs "outbox for client
/// ADDR full" through `tracing`, which (its `log` feature, no `tracing` subscriber in `sim`)
/// becomes a `log` record, throttled by the crate to one per 30 s. This logger takes the
/// crate's records and counts that one, so a drop is never silent: [`Session::close`] says a
/// client missed messages and the command exits 1. It counts the crate's lines, not the
/// messages (the crate does not say how many); the first drop is always logged (the
/// throttle starts open), so "none counted" means none dropped.
struct OutboxWatch;

/// The `log` target prefix of the crate's records.
const FOXGLOVE_TARGET: &str = "foxglove";

impl log::Log for OutboxWatch {
    fn enabled(&self, metadata: &log::Metadata) -> bool {
        metadata.target().starts_with(FOXGLOVE_TARGET) && metadata.level() <= log::Level::Info
    }
    fn log(&self, record: &log::Record) {
        if self.enabled(record.metadata()) && is_outbox_full(&record.args().to_string()) {
            OUTBOX_FULL.fetch_add(1, Ordering::Relaxed);
        }
    }
    fn flush(&self) {}
}

/// The crate's line for a full client queue: "outbox for client 127.0.0.1:50212 full".
fn is_outbox_full(line: &str) -> bool {
    line.starts_with("outbox for client ") && line.ends_with(" full")
}

/// Installs [`OutboxWatch`] as the process's logger (once; `sim` has no other).
fn watch_outboxes() {
    static WATCH: OutboxWatch = OutboxWatch;
    if log::set_logger(&WATCH).is_ok() {
        log::set_max_level(log::LevelFilter::Info);
    }
}

/// The line `sim` prints when a client's queue was full `times` times (none when 0).
fn outbox_report(times: u64) -> Option<String> {
    (times > 0).then(|| {
        format!(
            "sim: live: warning: a viewer fell behind and the live server dropped messages queued for it \
             (its queue was full {times} time(s); the server does not count the messages); the recording has them all. \
             Use --pace realtime (the default) or a lower --speed"
        )
    })
}

/// One MCAP channel of the current run, as advertised.
struct LiveChannel {
    raw: Arc<RawChannel>,
    topic: String,
    /// Every message of a latched topic, for later subscribers.
    latched: Option<Vec<(u64, Vec<u8>)>>,
    /// With `--wait`, the messages written before the first subscription.
    pending: VecDeque<(u64, Vec<u8>)>,
    pending_bytes: usize,
    subscribed_once: bool,
    /// The clients subscribed, by sink.
    sinks: Vec<SinkId>,
}

impl LiveChannel {
    fn send(&self, log_time_ns: u64, data: &[u8], sink: SinkId) {
        self.raw.log_with_meta_to_sink(data, PartialMetadata { log_time: Some(log_time_ns) }, Some(sink));
    }
}

/// The channels of the run being streamed.
#[derive(Default)]
struct Hub {
    /// By MCAP channel id.
    channels: HashMap<u16, LiveChannel>,
    /// The SDK's channel id → MCAP channel id.
    by_sdk_id: HashMap<ChannelId, u16>,
    /// `--wait`: keep every message until its channel's first subscription.
    keep_until_subscribed: bool,
    /// At most this many bytes kept per channel ([`KEPT_BYTES`]).
    kept_bytes: usize,
    /// Messages and bytes dropped from the kept ones, by topic, over all runs: reported at
    /// the end, and the command's exit status says so (never a silent drop).
    dropped: BTreeMap<String, (u64, usize)>,
}

impl Hub {
    fn new(keep_until_subscribed: bool) -> Self {
        Hub { keep_until_subscribed, kept_bytes: KEPT_BYTES, ..Hub::default() }
    }

    /// Keeps a message of channel `id` until its first subscription, dropping the oldest kept
    /// beyond [`Hub::kept_bytes`] (counted in [`Hub::dropped`]).
    fn keep(&mut self, id: u16, log_time_ns: u64, data: &[u8]) {
        let limit = self.kept_bytes;
        let Some(ch) = self.channels.get_mut(&id) else { return };
        ch.pending.push_back((log_time_ns, data.to_vec()));
        ch.pending_bytes += data.len();
        while ch.pending_bytes > limit {
            let Some((_, old)) = ch.pending.pop_front() else { break };
            ch.pending_bytes -= old.len();
            let d = self.dropped.entry(ch.topic.clone()).or_default();
            d.0 += 1;
            d.1 += old.len();
        }
    }

    /// One line per topic with dropped messages (empty: none dropped).
    fn drop_report(&self) -> Vec<String> {
        self.dropped
            .iter()
            .map(|(topic, (n, bytes))| {
                format!(
                    "sim: live: warning: {n} messages ({:.1} MiB) of {topic} were not streamed: they were written before the viewer subscribed to it, beyond the {} MiB kept per channel (the recording has them all)",
                    *bytes as f64 / f64::from(1 << 20),
                    self.kept_bytes >> 20
                )
            })
            .collect()
    }
}

fn lock(hub: &Mutex<Hub>) -> MutexGuard<'_, Hub> {
    hub.lock().unwrap_or_else(PoisonError::into_inner)
}

/// The server's subscription callbacks.
struct HubListener(Arc<Mutex<Hub>>);

impl ServerListener for HubListener {
    fn on_subscribe(&self, client: Client, channel: ChannelView) {
        let Some(sink) = client.sink_id() else { return };
        let mut hub = lock(&self.0);
        let keep = hub.keep_until_subscribed;
        let Some(id) = hub.by_sdk_id.get(&channel.id()).copied() else { return };
        let Some(ch) = hub.channels.get_mut(&id) else { return };
        if keep && !ch.subscribed_once {
            for (t, data) in std::mem::take(&mut ch.pending) {
                ch.send(t, &data, sink);
            }
            ch.pending_bytes = 0;
        } else if let Some(kept) = &ch.latched {
            for (t, data) in kept {
                ch.send(*t, data, sink);
            }
        }
        ch.subscribed_once = true;
        if !ch.sinks.contains(&sink) {
            ch.sinks.push(sink);
        }
    }

    fn on_unsubscribe(&self, client: Client, channel: ChannelView) {
        let Some(sink) = client.sink_id() else { return };
        let mut hub = lock(&self.0);
        let Some(id) = hub.by_sdk_id.get(&channel.id()).copied() else { return };
        if let Some(ch) = hub.channels.get_mut(&id) {
            ch.sinks.retain(|s| *s != sink);
        }
    }
}

/// The live server, for the whole command.
pub struct Session {
    server: Option<WebSocketServerHandle>,
    context: Arc<Context>,
    hub: Arc<Mutex<Hub>>,
    pace: Pace,
    speed: f64,
    wait: bool,
    quiet: bool,
    /// Runs started.
    runs: AtomicUsize,
}

impl Session {
    /// Starts the server when `--live` is given (`None` without it), on 127.0.0.1:`--live-port`,
    /// and prints its address; with `--wait`, waits for a client.
    pub fn start(a: &LiveArgs, about: &[(&str, String)], quiet: bool) -> anyhow::Result<Option<Session>> {
        if !a.live {
            return Ok(None);
        }
        watch_outboxes();
        let context = Context::new();
        let hub = Arc::new(Mutex::new(Hub::new(a.wait)));
        let info: HashMap<String, String> = about.iter().map(|(k, v)| (k.to_string(), v.clone())).collect();
        let mut server = WebSocketServer::new()
            .name("elbow-sim")
            .bind("127.0.0.1", a.port)
            .context(&context)
            .server_info(info)
            .listener(Arc::new(HubListener(hub.clone())));
        if a.pace == Pace::Fast || a.wait {
            server = server.message_backlog_size(BACKLOG_FAST);
        }
        let handle = server
            .start_blocking()
            .map_err(|e| anyhow::anyhow!("--live: cannot serve on 127.0.0.1:{}: {e}", a.port))?;
        let port = handle.port();
        // the address, always (a caller that asked for any port must learn which)
        eprintln!("sim: live: ws://127.0.0.1:{port} (Foxglove: Open connection → Foxglove WebSocket → ws://localhost:{port})");
        let session = Session { server: Some(handle), context, hub, pace: a.pace, speed: a.speed, wait: a.wait, quiet, runs: AtomicUsize::new(0) };
        if a.wait {
            if !quiet {
                eprintln!("sim: live: waiting for a client before running");
            }
            while session.clients() == 0 {
                std::thread::sleep(Duration::from_millis(20));
            }
        }
        Ok(Some(session))
    }

    fn clients(&self) -> usize {
        self.server.as_ref().map_or(0, WebSocketServerHandle::client_count)
    }

    /// Before each run: the previous run's channels unadvertised and a new session, so a
    /// viewer starts over at t = 0 (the last run's channels stay until the server stops).
    pub fn before_run(&self, name: &str) {
        let n = self.runs.fetch_add(1, Ordering::Relaxed);
        if let Some(s) = &self.server {
            if n > 0 {
                self.close_channels();
                s.clear_session(None);
            }
            s.publish_status(Status::info(format!("run {name}")).with_id("run"));
        }
        if !self.quiet {
            eprintln!("sim: live: streaming {name}");
        }
    }

    /// Unadvertises the channels of the run streamed last (outside the hub's lock: closing a
    /// channel calls the listener).
    fn close_channels(&self) {
        let channels: Vec<LiveChannel> = {
            let mut hub = lock(&self.hub);
            hub.by_sdk_id.clear();
            hub.channels.drain().map(|(_, c)| c).collect()
        };
        for c in channels {
            c.raw.close();
        }
    }

    /// The mirror of one run's writer.
    pub fn mirror(&self) -> Box<dyn schemas::Mirror> {
        Box::new(LiveMirror {
            hub: self.hub.clone(),
            context: self.context.clone(),
            schemas: BTreeMap::new(),
            pace: self.pace,
            speed: self.speed,
            start: None,
        })
    }

    /// After the runs: with `--wait`, serves until the clients disconnect; then stops. Returns
    /// whether messages were dropped (each topic's count printed on stderr): the command then
    /// exits with status 1.
    pub fn close(mut self) -> bool {
        if self.wait && self.clients() > 0 {
            if !self.quiet {
                eprintln!("sim: live: the runs are done; serving until the viewer disconnects (Ctrl-C to stop)");
            }
            while self.clients() > 0 {
                std::thread::sleep(Duration::from_millis(50));
            }
        }
        self.close_channels();
        if let Some(s) = self.server.take() {
            drop(s.stop());
        }
        let mut report = lock(&self.hub).drop_report();
        report.extend(outbox_report(OUTBOX_FULL.swap(0, Ordering::Relaxed)));
        for line in &report {
            eprintln!("{line}");
        }
        !report.is_empty()
    }
}

/// One run's mirror: advertises its channels, paces and sends its messages.
struct LiveMirror {
    hub: Arc<Mutex<Hub>>,
    context: Arc<Context>,
    /// By id: name, encoding, data.
    schemas: BTreeMap<u16, (String, String, Vec<u8>)>,
    pace: Pace,
    speed: f64,
    /// Wall-clock time of the run's first message.
    start: Option<Instant>,
}

impl schemas::Mirror for LiveMirror {
    fn schema(&mut self, id: u16, name: &str, encoding: &str, data: &[u8]) {
        self.schemas.insert(id, (name.into(), encoding.into(), data.into()));
    }

    fn channel(&mut self, id: u16, schema_id: u16, topic: &str, message_encoding: &str, metadata: &BTreeMap<String, String>) {
        let schema = self.schemas.get(&schema_id).map(|(n, e, d)| Schema::new(n.clone(), e.clone(), d.clone()));
        // advertised under the hub's lock, so that a subscription finds it
        let mut hub = lock(&self.hub);
        let built = ChannelBuilder::new(topic)
            .context(&self.context)
            .message_encoding(message_encoding)
            .schema(schema)
            .metadata(metadata.clone())
            .build_raw();
        match built {
            Ok(raw) => {
                hub.by_sdk_id.insert(raw.id(), id);
                let latched = schemas::topics::LATCHED.contains(&topic).then(Vec::new);
                hub.channels.insert(
                    id,
                    LiveChannel { raw, topic: topic.into(), latched, pending: VecDeque::new(), pending_bytes: 0, subscribed_once: false, sinks: Vec::new() },
                );
            }
            // (the recording is unaffected; the viewer misses this topic)
            Err(e) => eprintln!("sim: live: warning: {topic} is not streamed: {e}"),
        }
    }

    fn message(&mut self, channel_id: u16, _sequence: u32, log_time_ns: u64, data: &[u8]) {
        if self.pace == Pace::Realtime {
            let start = *self.start.get_or_insert_with(Instant::now);
            let after = Duration::try_from_secs_f64(log_time_ns as f64 * 1e-9 / self.speed).unwrap_or(Duration::MAX);
            if let Some(wait) = start.checked_add(after).and_then(|due| due.checked_duration_since(Instant::now())) {
                std::thread::sleep(wait);
            }
        }
        let mut hub = lock(&self.hub);
        let keep = hub.keep_until_subscribed;
        let Some(ch) = hub.channels.get_mut(&channel_id) else { return };
        if let Some(kept) = &mut ch.latched {
            kept.push((log_time_ns, data.to_vec()));
        }
        if keep && !ch.subscribed_once {
            hub.keep(channel_id, log_time_ns, data);
            return;
        }
        for sink in &ch.sinks {
            ch.send(log_time_ns, data, *sink);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A full client queue, as the `foxglove` crate logs it, is counted and reported (issue 29:
    /// those drops were silent), and nothing else the crate logs is. The record is the crate's
    /// own line, with its module as the target.
    #[test]
    fn a_full_client_queue_logged_by_the_server_is_counted_and_reported() {
        watch_outboxes();
        let before = OUTBOX_FULL.load(Ordering::Relaxed);
        let target = "foxglove::websocket::connected_client::send_lossy";
        log::info!(target: target, "Registered client 127.0.0.1:50212");
        log::info!(target: "other_crate", "outbox for client 127.0.0.1:50212 full");
        assert_eq!(OUTBOX_FULL.load(Ordering::Relaxed), before, "only the crate's full-queue line counts");
        log::info!(target: target, "outbox for client {} full", "127.0.0.1:50212");
        assert_eq!(OUTBOX_FULL.load(Ordering::Relaxed), before + 1);
        assert_eq!(outbox_report(0), None);
        let line = outbox_report(2).unwrap();
        assert!(line.contains("dropped messages") && line.contains("2 time(s)") && line.contains("the recording has them all"), "{line}");
    }

    /// Messages kept past the per-channel limit before the first subscription are counted per
    /// topic and reported (issue 29: they were dropped silently); nothing is reported when all
    /// fit. The channel is advertised on a context of its own, no server.
    #[test]
    fn messages_dropped_before_the_first_subscription_are_counted_and_reported() {
        let context = Context::new();
        let mut hub = Hub::new(true);
        hub.kept_bytes = 1000;
        let raw = ChannelBuilder::new("/tf").context(&context).message_encoding("cdr").build_raw().unwrap();
        hub.channels.insert(3, LiveChannel { raw, topic: "/tf".into(), latched: None, pending: VecDeque::new(), pending_bytes: 0, subscribed_once: false, sinks: Vec::new() });
        for t in 0..10 {
            hub.keep(3, t, &[0u8; 100]);
        }
        assert!(hub.drop_report().is_empty(), "1000 bytes fit");
        for t in 10..25 {
            hub.keep(3, t, &[0u8; 100]);
        }
        assert_eq!(hub.dropped["/tf"], (15, 1500));
        let ch = &hub.channels[&3];
        assert_eq!((ch.pending.len(), ch.pending_bytes, ch.pending[0].0), (10, 1000, 15), "the newest kept");
        let report = hub.drop_report();
        assert_eq!(report.len(), 1);
        assert!(report[0].contains("15 messages") && report[0].contains("of /tf were not streamed") && report[0].contains("the recording has them all"), "{}", report[0]);
    }
}
