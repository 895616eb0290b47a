//! Names of the event functions of a hybrid [`ArmSystem`] (see the table in `hybrid.rs`,
//! after Pfeiffer & Glocker 1996, ch. 5–6): function `i` belongs to contact `i / 2`, and
//! `i % 2` is ev0 or ev1 of that contact's CURRENT mode. Used to turn the driver's indices
//! (`IntegrateError::Chattering`) into contact names in the run's errors.

use crate::dynamics::contact::{ContactMode, ContactModel};

use super::arm::ArmSystem;

impl ArmSystem<'_> {
    /// "contact <name> (<kind> function)" for event function `i` in the current modes, e.g.
    /// "contact elbow4 (lift-off function)"; `None` if the run is not hybrid or `i` is out of
    /// range.
    pub fn describe_event_function(&self, i: usize) -> Option<String> {
        let nc = self.hybrid.as_ref().map_or(0, |h| 2 * h.contacts.len());
        if i >= nc {
            return self.describe_drive_event(i - nc);
        }
        let h = self.hybrid.as_ref()?;
        let c = h.contacts.get(i / 2)?;
        let first = i % 2 == 0;
        let kind = match (c.model, h.state.mode[i / 2]) {
            (ContactModel::Bilateral, _) => "bilateral: constant",
            (ContactModel::Compliant { .. }, _) => {
                if first {
                    "compliant touch-down/lift-off gap"
                } else {
                    "compliant normal-force-zero"
                }
            }
            (_, ContactMode::Separated | ContactMode::Bilateral) => {
                if first {
                    "touch-down"
                } else {
                    "separated: constant"
                }
            }
            (_, ContactMode::Sticking) => {
                if first {
                    "lift-off"
                } else {
                    "stick-to-slip"
                }
            }
            (_, ContactMode::Sliding) => {
                if first {
                    "lift-off"
                } else {
                    "slip-to-stick"
                }
            }
        };
        Some(format!("contact {} ({kind} function)", c.name()))
    }

    /// The driver's chattering description "event functions [i, j, …]" with each index
    /// replaced by [`Self::describe_event_function`]; any other text is returned unchanged.
    pub fn describe_event_functions(&self, text: &str) -> String {
        let Some(list) = text.strip_prefix("event functions [").and_then(|s| s.strip_suffix(']')) else {
            return text.to_string();
        };
        let mut names = Vec::new();
        for part in list.split(',').map(str::trim).filter(|s| !s.is_empty()) {
            match part.parse::<usize>().ok().and_then(|i| self.describe_event_function(i)) {
                Some(d) => names.push(d),
                None => return text.to_string(),
            }
        }
        if names.is_empty() {
            return text.to_string();
        }
        format!("event functions {}", names.join(", "))
    }
}
