//! Datasheet drives (`"drives"`) and the thermal model (`"thermal"`), validated and converted
//! to SI once. Conversions (exact factors):
//!
//! | datasheet | model | factor |
//! |---|---|---|
//! | torque constant k_M, mNm/A | K_t, N m/A | 1e-3 |
//! | speed constant k_n, rpm/V | K_e = 60 / (2π k_n), V s/rad | checked against K_t, not used (K_e = K_t) |
//! | terminal inductance, mH | L, H | 1e-3 |
//! | rotor inertia (+ gearhead inertia), g cm² | I_m, kg m² | 1e-7 |
//! | no-load speed n_0, rpm; no-load current I_0, mA | gear damping d_m = K_t I_0 / ω_0, N m s/rad (motor side) | ω_0 = 2π n_0 / 60, I_0 × 1e-3 |
//! | reduction i:1 | gear ratio k | 1 |
//! | thermal resistances, K/W; time constants, s | `dynamics::thermal::ThermalParams` | 1 |
//!
//! The no-load current is the motor's friction at no-load speed (maxon "Key information": the
//! friction torque M_R = k_M I_0); booked as viscous friction that matches it at ω_0 (the
//! only friction this drive model has; gear Coulomb friction is another model's). The speed
//! constant is the same machine constant in other units (k_n k_M = 30000/π for an ideal machine,
//! maxon "Key information"); a sheet's two values differ by their rounding, which would be
//! booked as a spurious conversion energy, so it is checked (2 %) and K_e = K_t.

use super::catalogue::catalogue;
use super::ctx::{positive, within, Ctx};
use super::spec::SceneSpec;
use super::spec_drive::{GearheadDatasheet, MotorDatasheet};
use crate::dynamics::motor::{DriveSpec, MotorParams};
use crate::dynamics::thermal::{Thermal, ThermalParams, ALPHA_COPPER_20};
use crate::dynamics::Model;
use crate::error::SceneError;

use super::spec::motor_bounds::{INDUCTANCE_MAX, INDUCTANCE_MIN, RESISTANCE_MAX, RESISTANCE_MIN};

/// The temperatures a scene may give (ambient, initial, reference, max winding), °C: from the
/// coldest to the hottest a DC motor is rated for, with margin.
pub const TEMPERATURE_MIN_C: f64 = -100.0;
pub const TEMPERATURE_MAX_C: f64 = 400.0;

/// What a joint's datasheet drive is, beyond its [`MotorParams`]: for `sim check` and the
/// limits monitor.
#[derive(Clone, Debug, PartialEq)]
pub struct DatasheetDrive {
    /// The catalogue names (motor, gearhead) or "datasheet values".
    pub what: String,
    /// Nominal voltage, V.
    pub nominal_voltage: f64,
    /// The gearhead's max efficiency, 0..1 (not modelled here; shown).
    pub gear_efficiency: Option<f64>,
    /// The gearhead's max continuous and intermittent output torque, N m.
    pub gear_torque_continuous: Option<f64>,
    pub gear_torque_intermittent: Option<f64>,
    /// The motor's thermal data (whether or not the scene turns the thermal model on).
    pub thermal: Option<ThermalParams>,
}

/// SI conversion of one datasheet (file context `c`, `field` the spec path for errors).
pub(super) fn motor_params(c: &Ctx, field: &str, m: &MotorDatasheet, g: Option<&GearheadDatasheet>, gfield: &str) -> Result<(MotorParams, Option<ThermalParams>), SceneError> {
    let num = |f: &str, x: f64, ok: &dyn Fn(f64) -> bool, why: &str| c.number(&format!("{field}.{f}"), x, ok, why);
    num("nominal_voltage_v", m.nominal_voltage_v, &positive, "must be > 0 V")?;
    let r = num("terminal_resistance_ohm", m.terminal_resistance_ohm, &within(RESISTANCE_MIN, RESISTANCE_MAX), "must be within the physical range 1e-6 ..= 1e3 ohm")?;
    let l = 1e-3 * num("terminal_inductance_mh", m.terminal_inductance_mh, &within(INDUCTANCE_MIN * 1e3, INDUCTANCE_MAX * 1e3), "must be within 1e-9 ..= 1e3 mH")?;
    let kt = 1e-3 * num("torque_constant_mnm_per_a", m.torque_constant_mnm_per_a, &positive, "must be > 0 mNm/A")?;
    let im = 1e-7 * num("rotor_inertia_gcm2", m.rotor_inertia_gcm2, &positive, "must be > 0 g cm^2")?;
    if let Some(kn) = m.speed_constant_rpm_per_v {
        num("speed_constant_rpm_per_v", kn, &positive, "must be > 0 rpm/V")?;
        let ke = 60.0 / (2.0 * std::f64::consts::PI * kn);
        if (ke / kt - 1.0).abs() > 0.02 {
            return Err(c.err(
                format!("{field}.speed_constant_rpm_per_v"),
                kn,
                format!("disagrees with the torque constant by {:.1} %: k_n k_M = 30000/π = 9549 rpm/V·mNm/A for one machine (here {:.0}); check the two values", 100.0 * (ke / kt - 1.0), kn * m.torque_constant_mnm_per_a),
            ));
        }
    }
    let d_m = match (m.no_load_speed_rpm, m.no_load_current_ma) {
        (Some(n0), Some(i0)) => {
            let w0 = num("no_load_speed_rpm", n0, &positive, "must be > 0 rpm")? * 2.0 * std::f64::consts::PI / 60.0;
            let i0 = 1e-3 * num("no_load_current_ma", i0, &|x| x >= 0.0, "must be >= 0 mA")?;
            kt * i0 / w0
        }
        (None, None) => 0.0,
        (Some(_), None) => return Err(c.err(format!("{field}.no_load_current_ma"), "(absent)", "give both the no-load speed and the no-load current (their ratio is the friction), or neither")),
        (None, Some(_)) => return Err(c.err(format!("{field}.no_load_speed_rpm"), "(absent)", "give both the no-load speed and the no-load current (their ratio is the friction), or neither")),
    };
    let (ratio, gear_inertia) = match g {
        Some(g) => {
            let k = c.number(&format!("{gfield}.reduction"), g.reduction, |x| (1.0..=1e4).contains(&x), "must be a reduction i:1 with 1 <= i <= 1e4")?;
            if let Some(e) = g.max_efficiency_percent {
                c.number(&format!("{gfield}.max_efficiency_percent"), e, |x| x > 0.0 && x <= 100.0, "must be in (0, 100] %")?;
            }
            for (f, x) in [("max_continuous_torque_nm", g.max_continuous_torque_nm), ("max_intermittent_torque_nm", g.max_intermittent_torque_nm)] {
                if let Some(x) = x {
                    c.number(&format!("{gfield}.{f}"), x, positive, "must be > 0 N m")?;
                }
            }
            let ig = g.inertia_gcm2.map(|x| c.number(&format!("{gfield}.inertia_gcm2"), x, |x| x >= 0.0, "must be >= 0 g cm^2")).transpose()?.unwrap_or(0.0);
            (k, 1e-7 * ig)
        }
        None => (1.0, 0.0),
    };
    let motor = MotorParams { torque_constant: kt, resistance: r, inductance: l, rotor_inertia: im + gear_inertia, gear_ratio: ratio, gear_damping: d_m };
    let thermal = thermal_params(c, field, m)?;
    Ok((motor, thermal))
}

/// The thermal block of a datasheet: all four of R_th1, R_th2, τ_w, τ_s (and the max winding
/// temperature), or none.
fn thermal_params(c: &Ctx, field: &str, m: &MotorDatasheet) -> Result<Option<ThermalParams>, SceneError> {
    let parts = [
        ("thermal_resistance_winding_housing_k_per_w", m.thermal_resistance_winding_housing_k_per_w),
        ("thermal_resistance_housing_ambient_k_per_w", m.thermal_resistance_housing_ambient_k_per_w),
        ("thermal_time_constant_winding_s", m.thermal_time_constant_winding_s),
        ("thermal_time_constant_motor_s", m.thermal_time_constant_motor_s),
        ("max_winding_temperature_c", m.max_winding_temperature_c),
    ];
    if parts.iter().all(|(_, x)| x.is_none()) {
        return Ok(None);
    }
    let mut v = [0.0; 5];
    for (k, (f, x)) in parts.iter().enumerate() {
        let Some(x) = x else {
            return Err(c.err(format!("{field}.{f}"), "(absent)", "the thermal data come complete: both thermal resistances, both time constants and the max winding temperature"));
        };
        v[k] = if k < 4 {
            c.number(&format!("{field}.{f}"), *x, |x| x > 0.0 && x <= 1e6, "must be > 0 (K/W or s) and at most 1e6")?
        } else {
            c.number(&format!("{field}.{f}"), *x, within(TEMPERATURE_MIN_C, TEMPERATURE_MAX_C), "must be within -100 ..= 400 °C")?
        };
    }
    let t_ref = m.resistance_reference_temperature_c.unwrap_or(25.0);
    c.number(&format!("{field}.resistance_reference_temperature_c"), t_ref, within(TEMPERATURE_MIN_C, TEMPERATURE_MAX_C), "must be within -100 ..= 400 °C")?;
    let alpha = m.resistance_temperature_coefficient_per_k.unwrap_or(ALPHA_COPPER_20);
    // R(T) > 0 over the whole admissible temperature range: α (20 + 100) < 1
    c.number(&format!("{field}.resistance_temperature_coefficient_per_k"), alpha, |x| (0.0..0.008).contains(&x), "must be within 0 ..< 0.008 /K (copper: 0.00393 at 20 °C)")?;
    Ok(Some(ThermalParams {
        r_winding_housing: v[0],
        r_housing_ambient: v[1],
        tau_winding: v[2],
        tau_housing: v[3],
        max_winding_temperature: v[4],
        reference_temperature: t_ref,
        alpha_20: alpha,
    }))
}

/// Applies the scene's datasheet drives to `motors` and `specs` (one per joint): each drive's
/// joints get its motor parameters and thermal data. Returns each joint's datasheet summary.
pub(super) fn apply_drives(c: &Ctx, spec: &SceneSpec, model: &Model, motors: &mut [MotorParams], specs: &mut [DriveSpec]) -> Result<Vec<Option<DatasheetDrive>>, SceneError> {
    let mut out: Vec<Option<DatasheetDrive>> = vec![None; model.nv];
    let cat = catalogue();
    for (k, d) in spec.drives.iter().enumerate() {
        let field = format!("drives[{k}]");
        if d.joints.is_empty() {
            return Err(c.err(format!("{field}.joints"), "[]", "needs at least one joint"));
        }
        let (mfield, motor, mname) = match (&d.motor, &d.motor_data) {
            (Some(name), None) => match cat.motor(name) {
                Some((e, m)) => (format!("{field}.motor"), m, e.name.clone()),
                None => return Err(c.err(format!("{field}.motor"), name, format!("no motor of that name in the catalogue (motors: {})", cat.motor_names().join(", ")))),
            },
            (None, Some(m)) => (format!("{field}.motor_data"), m, "datasheet values".to_string()),
            _ => return Err(c.err(format!("{field}.motor"), d.motor.as_deref().unwrap_or("(absent)"), "give exactly one of `motor` (a catalogue name) or `motor_data` (datasheet values)")),
        };
        let (gfield, gear, gname) = match (&d.gearhead, &d.gearhead_data) {
            (Some(name), None) => match cat.gearhead(name) {
                Some((e, g)) => (format!("{field}.gearhead"), Some(g), Some(e.name.clone())),
                None => return Err(c.err(format!("{field}.gearhead"), name, format!("no gearhead of that name in the catalogue (gearheads: {})", cat.gearhead_names().join(", ")))),
            },
            (None, Some(g)) => (format!("{field}.gearhead_data"), Some(g), Some("gearhead datasheet values".to_string())),
            (None, None) => (String::new(), None, None),
            (Some(n), Some(_)) => return Err(c.err(format!("{field}.gearhead"), n, "give at most one of `gearhead` (a catalogue name) or `gearhead_data`")),
        };
        let (params, thermal) = motor_params(c, &mfield, motor, gear, &gfield)?;
        let summary = DatasheetDrive {
            what: match gname {
                Some(g) => format!("{mname} + {g}"),
                None => mname,
            },
            nominal_voltage: motor.nominal_voltage_v,
            gear_efficiency: gear.and_then(|g| g.max_efficiency_percent).map(|e| e / 100.0),
            gear_torque_continuous: gear.and_then(|g| g.max_continuous_torque_nm),
            gear_torque_intermittent: gear.and_then(|g| g.max_intermittent_torque_nm),
            thermal,
        };
        for (i, name) in d.joints.iter().enumerate() {
            let j = c.dof(&format!("{field}.joints[{i}]"), model, name)?;
            if out[j].is_some() {
                return Err(c.err(format!("{field}.joints[{i}]"), name, "already has a datasheet drive (a joint is in one drive only)"));
            }
            motors[j] = params;
            specs[j].back_emf_constant = None;
            specs[j].thermal = thermal;
            out[j] = Some(summary.clone());
        }
    }
    Ok(out)
}

/// The thermal model, when the scene turns it on: every motor (passive joints aside) needs its
/// thermal data. `r_ref` is each joint's terminal resistance at its reference temperature.
pub(super) fn build_thermal(c: &Ctx, spec: &SceneSpec, model: &Model, specs: &[DriveSpec], r_ref: &[f64]) -> Result<Option<Thermal>, SceneError> {
    let Some(t) = &spec.thermal else {
        return Ok(None);
    };
    let ambient = c.number("thermal.ambient_temperature_c", t.ambient_temperature_c, within(TEMPERATURE_MIN_C, TEMPERATURE_MAX_C), "must be within -100 ..= 400 °C")?;
    let initial = match t.initial_temperature_c {
        Some(x) => c.number("thermal.initial_temperature_c", x, within(TEMPERATURE_MIN_C, TEMPERATURE_MAX_C), "must be within -100 ..= 400 °C")?,
        None => ambient,
    };
    for (j, s) in specs.iter().enumerate() {
        if !s.passive && s.thermal.is_none() {
            let joint = &model.bodies[j].joint;
            return Err(c.err(
                "thermal",
                "(on)",
                format!("joint `{joint}`'s motor has no thermal data: give it a datasheet drive (`drives`: a catalogue motor, or `motor_data` with both thermal resistances, both time constants and the max winding temperature)"),
            ));
        }
    }
    Ok(Some(Thermal { params: specs.iter().map(|s| if s.passive { None } else { s.thermal }).collect(), ambient, initial, r_ref: r_ref.to_vec() }))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ctx() -> Ctx<'static> {
        Ctx { file: "test.json" }
    }

    /// The conversions against values worked by hand for the RE 40 (148877) with the GP 42 C
    /// 12:1 (203115): K_t = 60.3 mNm/A = 0.0603 N m/A; L = 0.329 mH = 3.29e-4 H;
    /// I_m = (142 + 15) g cm² = 157e-7 kg m²; ω_0 = 7580 rpm = 793.775 rad/s, so
    /// d_m = 0.0603 × 0.069 / 793.775 = 5.2417e-6 N m s/rad; reflected: K_m = 0.7236 N m/A,
    /// J_m = 157e-7 × 144 = 2.2608e-3 kg m², D_m = 7.548e-4 N m s/rad; C_w = 41.6/1.93 =
    /// 21.554 J/K, C_h = 1120/4.65 = 240.86 J/K; R(25 °C) = 1.16 ohm.
    #[test]
    fn datasheet_units_convert_to_the_hand_values() {
        let cat = catalogue();
        let (_, m) = cat.motor("maxon-re40-148877").unwrap();
        let (_, g) = cat.gearhead("maxon-gp42c-203115").unwrap();
        let (p, th) = motor_params(&ctx(), "m", m, Some(g), "g").unwrap();
        let close = |a: f64, b: f64, rel: f64| (a - b).abs() <= rel * b.abs();
        assert!(close(p.torque_constant, 0.0603, 1e-15) && close(p.resistance, 1.16, 0.0) && close(p.inductance, 3.29e-4, 1e-15));
        assert!(close(p.rotor_inertia, 157e-7, 1e-15) && p.gear_ratio == 12.0);
        assert!(close(p.gear_damping, 5.2417e-6, 1e-4), "{}", p.gear_damping);
        assert!(close(p.km(), 0.7236, 1e-14) && close(p.jm(), 2.2608e-3, 1e-14) && close(p.dm(), 7.548e-4, 1e-3), "{} {} {}", p.km(), p.jm(), p.dm());
        let th = th.unwrap();
        assert!(close(th.c_winding(), 21.554, 1e-4) && close(th.c_housing(), 240.86, 1e-4));
        assert_eq!((th.max_winding_temperature, th.reference_temperature, th.alpha_20), (155.0, 25.0, 0.00393));
    }

    /// A mistyped datasheet is refused naming the field and the value.
    #[test]
    fn inconsistent_or_incomplete_datasheets_are_refused() {
        let (_, m) = catalogue().motor("maxon-re40-148877").unwrap();
        let bad = MotorDatasheet { speed_constant_rpm_per_v: Some(185.0), ..m.clone() };
        let e = motor_params(&ctx(), "drives[0].motor_data", &bad, None, "").unwrap_err().to_string();
        assert!(e.contains("drives[0].motor_data.speed_constant_rpm_per_v") && e.contains("185"), "{e}");
        let partial = MotorDatasheet { thermal_time_constant_motor_s: None, ..m.clone() };
        let e = motor_params(&ctx(), "d", &partial, None, "").unwrap_err().to_string();
        assert!(e.contains("d.thermal_time_constant_motor_s") && e.contains("complete"), "{e}");
        let zero = MotorDatasheet { terminal_inductance_mh: 0.0, ..m.clone() };
        assert!(motor_params(&ctx(), "d", &zero, None, "").unwrap_err().to_string().contains("d.terminal_inductance_mh"));
        let g = GearheadDatasheet { reduction: 0.5, max_efficiency_percent: None, inertia_gcm2: None, max_continuous_torque_nm: None, max_intermittent_torque_nm: None };
        assert!(motor_params(&ctx(), "d", m, Some(&g), "drives[0].gearhead_data").unwrap_err().to_string().contains("drives[0].gearhead_data.reduction"));
    }
}
