//! The unit of every field of our topics: one table, read by the writer (each channel's MCAP
//! metadata `units`, a JSON object field → unit), by the exporters (CSV headers, Parquet field
//! metadata) and by the viewers' layouts (axis and series labels).
//!
//! Units are SI with radians, written as in the SI brochure (BIPM, 9th ed., 2019, §5: `N·m`,
//! `m/s`, `rad/s`). Field paths are the message's own (`actual.x`; an array's unit is that of
//! each entry). Fields without a unit (names, mode codes, event kinds) are absent.

use std::collections::BTreeMap;

use crate::topics;

/// `(field, unit)` of every field of `topic` that has a unit, in message order.
pub fn fields(topic: &str) -> &'static [(&'static str, &'static str)] {
    match topic {
        topics::JOINT_STATES => &[("position", "rad"), ("velocity", "rad/s"), ("effort", "N·m")],
        topics::MOTORS => &[
            ("time", "s"),
            ("current", "A"),
            ("voltage", "V"),
            ("back_emf", "V"),
            ("electric_power", "W"),
            ("torque", "N·m"),
        ],
        topics::MOTOR_TEMPERATURES => &[("time", "s"), ("winding_temperature", "°C"), ("housing_temperature", "°C"), ("resistance", "Ω"), ("copper_loss", "W")],
        topics::CONSTRAINTS => &[("time", "s"), ("normal_force", "N"), ("position", "m"), ("velocity", "m/s")],
        topics::HAND => &[
            ("time", "s"),
            ("actual.x", "m"),
            ("actual.y", "m"),
            ("actual.z", "m"),
            ("desired.x", "m"),
            ("desired.y", "m"),
            ("desired.z", "m"),
            ("error.x", "m"),
            ("error.y", "m"),
            ("error.z", "m"),
            ("error_norm", "m"),
        ],
        topics::ENERGY => &[
            ("time", "s"),
            ("link_work", "J"),
            ("electric_energy", "J"),
            ("link_work_total", "J"),
            ("electric_energy_total", "J"),
            ("kinetic", "J"),
            ("potential", "J"),
            ("magnetic", "J"),
            ("resistive_loss", "J"),
            ("friction_loss", "J"),
            ("balance_residual", "J"),
            ("gear_friction_loss", "J"),
        ],
        topics::CONTACTS => &[
            ("time", "s"),
            ("gap", "m"),
            ("gap_rate", "m/s"),
            ("normal_force", "N"),
            ("friction_force_t1", "N"),
            ("friction_force_t2", "N"),
            ("slip_velocity_t1", "m/s"),
            ("slip_velocity_t2", "m/s"),
            ("impact_loss", "J"),
            ("friction_work", "J"),
            ("damping_loss", "J"),
        ],
        topics::CONTACT_FRICTION => &[("time", "s"), ("slip_speed", "m/s"), ("friction_use", "1")],
        topics::CONTACT_EVENTS => &[
            ("time", "s"),
            ("impulse", "N·s"),
            ("energy_lost", "J"),
            ("gap_rate_before", "m/s"),
            ("gap_rate_after", "m/s"),
        ],
        topics::SUPPLY => &[
            ("time", "s"),
            ("power", "W"),
            ("bus_power", "W"),
            ("energy", "J"),
            ("regenerated", "J"),
            ("dumped", "J"),
            ("loss", "J"),
        ],
        topics::TF => &[
            ("transforms.translation.x", "m"),
            ("transforms.translation.y", "m"),
            ("transforms.translation.z", "m"),
        ],
        _ => &[],
    }
}

/// The unit of `field` of `topic` (a message path: `current`, `actual.x`), if it has one.
pub fn unit(topic: &str, field: &str) -> Option<&'static str> {
    fields(topic).iter().find(|(f, _)| *f == field).map(|(_, u)| *u)
}

/// The MCAP channel metadata of `topic`: `units` = a JSON object of [`fields`] (empty map when
/// the topic has no unit-bearing field).
pub fn channel_metadata(topic: &str) -> BTreeMap<String, String> {
    let table = fields(topic);
    let mut out = BTreeMap::new();
    if !table.is_empty() {
        let map: serde_json::Map<String, serde_json::Value> =
            table.iter().map(|(f, u)| (f.to_string(), serde_json::Value::from(*u))).collect();
        out.insert("units".to_string(), serde_json::Value::Object(map).to_string());
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every floating-point field of our own messages (from each schema's descriptor, nested
    /// structs as `a.b`) is in the table, and every entry names such a field.
    #[test]
    fn the_table_names_exactly_the_float_fields_of_each_message() {
        use crate::messages::Message;
        use prost_reflect::{DescriptorPool, Kind, MessageDescriptor};
        fn floats(prefix: &str, m: &MessageDescriptor, out: &mut Vec<String>) {
            for f in m.fields() {
                let p = if prefix.is_empty() { f.name().to_string() } else { format!("{prefix}.{}", f.name()) };
                match f.kind() {
                    Kind::Double | Kind::Float => out.push(p),
                    Kind::Message(inner) => floats(&p, &inner, out),
                    _ => {}
                }
            }
        }
        fn check<M: Message>(topic: &str) {
            let pool = DescriptorPool::decode(M::schema_data().as_slice()).unwrap();
            let desc = pool.get_message_by_name(&M::schema_name()).unwrap();
            let mut found = Vec::new();
            floats("", &desc, &mut found);
            found.sort();
            let mut listed: Vec<String> = fields(topic).iter().map(|(f, _)| f.to_string()).collect();
            listed.sort();
            assert_eq!(found, listed, "{topic}");
        }
        check::<crate::MotorState>(topics::MOTORS);
        check::<crate::ConstraintState>(topics::CONSTRAINTS);
        check::<crate::HandState>(topics::HAND);
        check::<crate::EnergyState>(topics::ENERGY);
        check::<crate::ContactState>(topics::CONTACTS);
        check::<crate::ContactEventMsg>(topics::CONTACT_EVENTS);
        check::<crate::ContactFriction>(topics::CONTACT_FRICTION);
        check::<crate::MotorThermalState>(topics::MOTOR_TEMPERATURES);
    }

    #[test]
    fn channel_metadata_is_a_json_object_of_units() {
        let m = channel_metadata(topics::MOTORS);
        let v: serde_json::Value = serde_json::from_str(&m["units"]).unwrap();
        assert_eq!(v["current"], "A");
        assert_eq!(v["torque"], "N·m");
        assert!(channel_metadata(topics::ROBOT_DESCRIPTION).is_empty());
        assert_eq!(unit(topics::HAND, "error.z"), Some("m"));
        assert_eq!(unit(topics::MOTORS, "name"), None);
    }
}
