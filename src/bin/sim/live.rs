//! `sim --live`: stream the runs to the Foxglove app while they compute, over Foxglove's
//! WebSocket protocol (<https://github.com/foxglove/ws-protocol>, docs/spec.md; served by the
//! `foxglove` crate's `WebSocketServer`, subprotocol `foxglove.sdk.v1` in its version 0.30).
//!
//! What is streamed is what is written: the writer hands every record to a
//! [`schemas::Mirror`] with the bytes it writes to the MCAP, and the mirror advertises one raw
//! channel per MCAP channel (the same topic, message encoding, schema name, encoding and bytes,
//! and channel metadata: the `units`) and sends every message with its log time as the
//! message's timestamp. The Foxglove app therefore sees the topics and schemas the file has. The
//! recording does not depend on the mirror (`tests/e2e/live.rs` compares the files byte for byte).
//!
//! - **Pacing** (`--pace realtime`, the default): a message at simulated time t is sent no
//!   earlier than the run's wall-clock start + t / `--speed`. The mirror waits on the writer's
//!   thread; the writer's bounded queue then holds the simulation, which never reads the clock
//!   for its numbers. `--pace fast` sends as soon as written.
//! - **Latched topics** ([`schemas::topics::LATCHED`]: `/robot_description`, `/scene`, written
//!   once at t = 0) are kept and sent again to every client that subscribes later, so a viewer
//!   that connects mid-run still draws the arm (ROS calls such topics latched; the protocol has
//!   no such notion, the server does it per subscription).
//! - **`--wait`**: no run starts before a client is connected; every message of a channel is then
//!   kept until the channel's first subscription and sent to it then (at most `KEPT_BYTES`,
//!   64 MiB, per channel: beyond, the oldest are dropped, counted per topic, reported on stderr
//!   when the command ends, and the exit status is 1), so a client that subscribes as channels
//!   appear receives every message of the run. After the runs the server stays up until the clients disconnect
//!   (the queued messages reach them), or Ctrl-C.
//! - **A client that falls behind** loses the oldest messages queued for it inside the crate
//!   (`message_backlog_size`); the crate only logs it, so `server::OutboxWatch` (the process's
//!   `log` logger) watches for that line and the command says so and exits 1.
//! - **Several runs** (`sim` alone runs six) are streamed one at a time, in order, on the same
//!   topics as their files (prefixing topics would not separate them in the 3D panel: the frames
//!   of `/tf` are the same in every run); each run starts a new session (`serverInfo` with a new
//!   session id), so the app starts over at t = 0. `--run NAME` picks one.
//! - **Metadata**: the protocol carries no metadata records; the MCAP's (scene, URDF, setup) are
//!   in the file. The server's `serverInfo` metadata names the scene(s), the runs and the tool.

use std::path::Path;

/// `--pace`: how fast a run is streamed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Pace {
    /// A message at simulated time t is sent no earlier than the run's start + t / --speed.
    Realtime,
    /// As fast as the run computes.
    Fast,
}

/// The flags of `sim --live` (on `sim` alone and `sim run`).
#[derive(Debug, Clone, clap::Args)]
pub struct LiveArgs {
    /// Stream the runs to the Foxglove app while they compute (Open connection → Foxglove
    /// WebSocket → ws://localhost:8765); the recordings are the same. Several runs are streamed
    /// one after another. Needs a build with the feature `live`.
    #[arg(long)]
    pub live: bool,
    /// The port of the live server (0: any free port); the address is printed on stderr.
    #[arg(long = "live-port", value_name = "PORT", default_value_t = 8765, requires = "live")]
    pub port: u16,
    /// realtime: simulated time t is sent at wall start + t / --speed; fast: as computed.
    #[arg(long, value_enum, value_name = "PACE", default_value_t = Pace::Realtime, requires = "live")]
    pub pace: Pace,
    /// With --pace realtime, simulated seconds per wall-clock second.
    #[arg(long, value_name = "FACTOR", default_value_t = 1.0, value_parser = positive_factor, requires = "live")]
    pub speed: f64,
    /// Start no run before a viewer is connected, send it every message, and after the runs
    /// serve until it disconnects (or Ctrl-C).
    #[arg(long, requires = "live")]
    pub wait: bool,
}

/// `--speed`: a positive factor.
fn positive_factor(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(x) if x > 0.0 && x.is_finite() => Ok(x),
        _ => Err(format!("{s:?} is not a positive factor")),
    }
}

impl LiveArgs {
    /// The wall-clock budget of a run of `duration_s` simulated seconds: `budget` plus the most
    /// time pacing can take, `duration_s / speed` (an upper bound: a run slower than real time
    /// gets that much more time than without `--live`; README, "Watch a run live").
    pub fn budget(&self, budget: sim::run::Budget, duration_s: f64) -> sim::run::Budget {
        if !self.live || self.pace == Pace::Fast {
            return budget;
        }
        let paced = std::time::Duration::try_from_secs_f64(duration_s / self.speed).unwrap_or(std::time::Duration::MAX);
        sim::run::Budget { wall_time: budget.wall_time.saturating_add(paced), ..budget }
    }
}

/// The command that builds `sim` with the live view.
#[cfg(not(feature = "live"))]
pub const BUILD_HINT: &str = "cargo run --release --features live --bin sim -- --live";

#[cfg(not(feature = "live"))]
mod server {
    //! Without the feature `live`: `--live` is an error that says how to get it.
    use super::LiveArgs;

    /// Never made without the feature.
    pub enum Session {}

    impl Session {
        /// `None` without `--live`; with it, the error naming the feature.
        pub fn start(a: &LiveArgs, _about: &[(&str, String)], _quiet: bool) -> anyhow::Result<Option<Session>> {
            if a.live {
                anyhow::bail!(
                    "--live needs the live view, which this build of sim leaves out: build it with the feature `live` ({})",
                    super::BUILD_HINT
                );
            }
            Ok(None)
        }

        pub fn before_run(&self, _name: &str) {
            match *self {}
        }

        pub fn mirror(&self) -> Box<dyn schemas::Mirror> {
            match *self {}
        }

        pub fn close(self) -> bool {
            match self {}
        }
    }
}

#[cfg(feature = "live")]
mod server;

pub use server::Session;

/// What the server says about itself (`serverInfo` metadata): the tool, and for each scene
/// its runs.
pub fn about(scenes: &[(&sim::scene::Scene, Vec<String>)], out: &Path) -> Vec<(&'static str, String)> {
    let mut v = vec![("tool", sim::record::TOOL.to_string()), ("recording_format", schemas::FORMAT_VERSION.to_string())];
    let names: Vec<String> = scenes.iter().flat_map(|(s, runs)| runs.iter().map(move |r| format!("{}-{r}", s.spec().name))).collect();
    v.push(("runs", names.join(", ")));
    v.push(("out", out.display().to_string()));
    v
}
