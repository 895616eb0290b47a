//! Exit statuses, the same in both tools, and how both print an error ([`message`]).
//!
//! - [`SUCCESS`] (0): done, and nothing to report.
//! - [`FAILED`] (1): the work ran to its end but its result is a failure the caller must see: a
//!   run stopped numerically (its recording says when and why), `analyze diff` found
//!   differences, unreadable recordings were left out with `--skip-bad`.
//! - [`BAD_INPUT`] (2): bad input, nothing (more) done: the command line (clap's own status), a
//!   scene or URDF, an unreadable recording, an I/O error.

pub const SUCCESS: u8 = 0;
pub const FAILED: u8 = 1;
pub const BAD_INPUT: u8 = 2;

/// The error and its causes, `: `-separated, leaving out a cause whose text is already in the
/// message (errors that print their source would repeat it: an I/O error would say its OS
/// reason twice).
pub fn message(err: &anyhow::Error) -> String {
    let mut msg = err.to_string();
    for cause in err.chain().skip(1) {
        let c = cause.to_string();
        if !msg.contains(&c) {
            msg.push_str(": ");
            msg.push_str(&c);
        }
    }
    msg
}

#[cfg(test)]
mod tests {
    /// An I/O error from `schemas` names the path and the OS reason once.
    #[test]
    fn a_cause_already_in_the_message_is_not_repeated() {
        let io = schemas::Error::Io {
            file: "out/x.mcap".into(),
            op: "writing",
            source: std::io::Error::from_raw_os_error(28),
        };
        let e = anyhow::Error::from(io).context("run `free`");
        assert_eq!(super::message(&e), "run `free`: out/x.mcap: writing: No space left on device (os error 28)");
    }
}
