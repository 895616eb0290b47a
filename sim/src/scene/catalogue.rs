//! The shipped drive catalogue (`sim/catalogue/drives.json`): a few real DC motors and
//! gearheads by name, each value paired with the datasheet line it comes from (the file's
//! `about` says how the values were transcribed). A scene names an entry in a datasheet drive
//! (`drives[k].motor`, `drives[k].gearhead`); its values then enter exactly as if written in
//! `motor_data` / `gearhead_data`.

use std::collections::BTreeMap;
use std::sync::OnceLock;

use serde::Deserialize;

use super::spec_drive::{GearheadDatasheet, MotorDatasheet};

/// The catalogue file, built in.
pub const CATALOGUE_JSON: &str = include_str!("../../catalogue/drives.json");

/// Where an entry's numbers come from.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Source {
    pub url: String,
    pub document: String,
    /// Whether (and against which edition) the values were checked against the document.
    pub checked: String,
}

/// One entry: a name, a description, its source, and each value with its datasheet line.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Entry {
    pub name: String,
    pub description: String,
    pub source: Source,
    /// Field (as in `motor_data` / `gearhead_data`) → (value, datasheet line).
    pub values: BTreeMap<String, (f64, String)>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct File {
    #[allow(dead_code)] // the file's own documentation
    about: String,
    motors: Vec<Entry>,
    gearheads: Vec<Entry>,
}

/// The parsed catalogue: its entries and their values as datasheets.
#[derive(Debug)]
pub struct Catalogue {
    pub motors: Vec<(Entry, MotorDatasheet)>,
    pub gearheads: Vec<(Entry, GearheadDatasheet)>,
}

/// The values of `e` as the datasheet type `T` (its fields, unknown ones refused).
fn datasheet<T: serde::de::DeserializeOwned>(e: &Entry) -> Result<T, String> {
    let map: serde_json::Map<String, serde_json::Value> = e.values.iter().map(|(k, (v, _))| (k.clone(), serde_json::json!(v))).collect();
    serde_json::from_value(serde_json::Value::Object(map)).map_err(|err| format!("catalogue entry {}: {err}", e.name))
}

fn parse() -> Result<Catalogue, String> {
    let f: File = serde_json::from_str(CATALOGUE_JSON).map_err(|e| format!("sim/catalogue/drives.json: {e}"))?;
    let motors = f.motors.into_iter().map(|e| datasheet(&e).map(|d| (e, d))).collect::<Result<_, _>>()?;
    let gearheads = f.gearheads.into_iter().map(|e| datasheet(&e).map(|d| (e, d))).collect::<Result<_, _>>()?;
    Ok(Catalogue { motors, gearheads })
}

/// The built-in catalogue (parsed once; its tests guarantee that it parses).
pub fn catalogue() -> &'static Catalogue {
    static CAT: OnceLock<Catalogue> = OnceLock::new();
    CAT.get_or_init(|| parse().unwrap_or_else(|e| panic!("the built-in catalogue: {e}")))
}

impl Catalogue {
    pub fn motor(&self, name: &str) -> Option<&(Entry, MotorDatasheet)> {
        self.motors.iter().find(|(e, _)| e.name == name)
    }
    pub fn gearhead(&self, name: &str) -> Option<&(Entry, GearheadDatasheet)> {
        self.gearheads.iter().find(|(e, _)| e.name == name)
    }
    pub fn motor_names(&self) -> Vec<&str> {
        self.motors.iter().map(|(e, _)| e.name.as_str()).collect()
    }
    pub fn gearhead_names(&self) -> Vec<&str> {
        self.gearheads.iter().map(|(e, _)| e.name.as_str()).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The file parses; every entry has a source and every value a datasheet line; names are
    /// unique.
    #[test]
    fn every_value_has_its_datasheet_line() {
        let c = parse().expect("the catalogue parses");
        assert!(c.motors.len() >= 2 && c.gearheads.len() >= 2);
        let mut names: Vec<&str> = c.motor_names().into_iter().chain(c.gearhead_names()).collect();
        for (e, _) in c.motors.iter().map(|(e, d)| (e, d as &dyn std::fmt::Debug)).chain(c.gearheads.iter().map(|(e, d)| (e, d as &dyn std::fmt::Debug))) {
            assert!(e.source.url.starts_with("https://") && !e.source.document.is_empty() && !e.source.checked.is_empty(), "{}", e.name);
            for (k, (v, line)) in &e.values {
                assert!(v.is_finite() && *v > 0.0, "{}: {k} = {v}", e.name);
                assert!(line.len() > 4, "{}: {k} has no datasheet line", e.name);
            }
        }
        names.sort();
        let n = names.len();
        names.dedup();
        assert_eq!(names.len(), n, "duplicate names");
    }

    /// The datasheets' own identities, which a mistyped value breaks: k_n k_M = 30000/π
    /// (rpm/V × mNm/A; 2 %: the sheets round to three digits), the no-load speed
    /// ω_0 = (U_N − R I_0) / k_M (1 %) where the sheet's no-load pair is given, and the thermal
    /// data complete.
    #[test]
    fn the_motor_entries_satisfy_the_datasheet_identities() {
        for (e, d) in &catalogue().motors {
            let kn = d.speed_constant_rpm_per_v.expect("speed constant");
            let prod = kn * d.torque_constant_mnm_per_a;
            assert!((prod / (30000.0 / std::f64::consts::PI) - 1.0).abs() < 0.02, "{}: k_n k_M = {prod}", e.name);
            // the no-load pair is optional (an entry leaves it out when it breaks this identity)
            if let (Some(i0), Some(n0)) = (d.no_load_current_ma, d.no_load_speed_rpm) {
                let w0 = (d.nominal_voltage_v - d.terminal_resistance_ohm * i0 * 1e-3) / (d.torque_constant_mnm_per_a * 1e-3);
                let rpm = w0 * 60.0 / (2.0 * std::f64::consts::PI);
                assert!((rpm / n0 - 1.0).abs() < 0.01, "{}: {rpm} rpm", e.name);
            }
            assert!(d.thermal_resistance_housing_ambient_k_per_w.is_some() && d.thermal_time_constant_motor_s.is_some() && d.max_winding_temperature_c.is_some(), "{}", e.name);
        }
    }
}
