//! The signals of one run in Rerun, for its time-series views: per joint the motor current and
//! voltage, the electric energy `E_j` and the link work `W_j`; per contact the normal force,
//! `|f_t|`, the slip speed, `|f_t| / (μ f_n)` and the mode code; the energy totals and the
//! balance residual (the recorded `E − (ΔT + ΔV + ΔL i²/2 + losses)`, see `crate::metrics`).
//! Each a `Scalars` entity per sample with its static `SeriesLines` style (name, colour,
//! width), named by [`signal`] (the unit in the first path part).

use super::chunk::{f32_lists, f64_each, rgba, str_lists, u32_lists, Chunk, Index};
use super::contacts::ContactForces;
use super::entities::{palette, Paths, PALETTE};
use super::run::{escape, ns, Run};

const SCALARS: &str = "rerun.archetypes.Scalars";
const SERIES: &str = "rerun.archetypes.SeriesLines";

/// The signal groups and their entity names (the first path part; the unit after `_`).
pub mod signal {
    pub const CURRENT: &str = "current_A";
    pub const VOLTAGE: &str = "voltage_V";
    pub const NORMAL_FORCE: &str = "normal_force_N";
    pub const FRICTION_FORCE: &str = "friction_force_N";
    pub const CONTACT_MODE: &str = "contact_mode";
    /// The slip speed `|v_t|` of a unilateral or compliant contact, m/s.
    pub const SLIP_SPEED: &str = "slip_speed_mps";
    /// `|f_t| / (μ f_n)`: 1 on the friction cone (sliding), below it sticking (samples with
    /// `f_n > 0` only).
    pub const FRICTION_RATIO: &str = "friction_ratio";
    pub const ELECTRIC_ENERGY: &str = "electric_energy_J";
    pub const LINK_WORK: &str = "link_work_J";
    pub const ENERGY: &str = "energy_J";
    pub const RESIDUAL: &str = "energy_residual_J";
}

/// How an energy term is read from `/energy`.
pub type EnergyTerm = fn(&schemas::EnergyState) -> f64;

/// The energy totals: entity name, series label, and how to get it from `/energy`.
pub const ENERGY_TERMS: [(&str, &str, EnergyTerm); 8] = [
    ("electric-in", "electric energy in, Σ E_j", |e| e.electric_energy_total),
    ("link-work", "link work, Σ W_j", |e| e.link_work_total),
    ("kinetic", "kinetic T", |e| e.kinetic),
    ("potential", "potential V", |e| e.potential),
    ("magnetic", "magnetic L i²/2", |e| e.magnetic),
    ("resistive-loss", "resistive loss", |e| e.resistive_loss),
    ("friction-loss", "friction loss (joints D and gears D_m)", |e| e.friction_loss),
    ("gear-friction-loss", "gear friction loss", |e| e.gear_friction_loss),
];

/// A time series: `Scalars` per sample plus its static `SeriesLines` style (name, colour).
fn series(path: String, times: &[i64], values: Vec<f64>, name: &str, color: u32, width: f32) -> [Chunk; 2] {
    [
        Chunk::new(&path, Index::SimTime(times.to_vec())).with(SCALARS, "scalars", "rerun.components.Scalar", f64_each(&values)),
        Chunk::new(&path, Index::Static)
            .with(SERIES, "colors", "rerun.components.Color", u32_lists(&[vec![color]]))
            .with(SERIES, "names", "rerun.components.Name", str_lists(&[vec![name.to_string()]]))
            .with(SERIES, "widths", "rerun.components.StrokeWidth", f32_lists(&[vec![width]])),
    ]
}


/// The typed scalar entities of a run ([`signal`]).
pub fn signal_chunks(run: &Run, paths: &Paths, forces: &ContactForces) -> Vec<Chunk> {
    let (f_n, f_t, modes) = forces;
    let modes = modes.as_deref();
    use signal::*;
    let mut out = Vec::new();
    let motor_t: Vec<i64> = run.motors.iter().map(|(t, _)| ns(*t)).collect();
    let energy_t: Vec<i64> = run.energy.iter().map(|(t, _)| ns(*t)).collect();
    let width = 1.5;
    for (j, joint) in run.joints.iter().enumerate() {
        let color = palette(j);
        let jp = escape(joint);
        let current = run.motors.iter().map(|(_, m)| m.current[j]).collect();
        out.extend(series(format!("{}/{jp}", paths.signal(CURRENT)), &motor_t, current, &format!("{joint} [A]"), color, width));
        if run.whole.voltage_every_joint {
            let v = run.motors.iter().map(|(_, m)| m.voltage[j]).collect();
            out.extend(series(format!("{}/{jp}", paths.signal(VOLTAGE)), &motor_t, v, &format!("{joint} [V]"), color, width));
        }
        let e = run.energy.iter().map(|(_, e)| e.electric_energy[j]).collect();
        out.extend(series(format!("{}/{jp}", paths.signal(ELECTRIC_ENERGY)), &energy_t, e, &format!("E {joint} [J]"), color, width));
        let w = run.energy.iter().map(|(_, e)| e.link_work[j]).collect();
        out.extend(series(format!("{}/{jp}", paths.signal(LINK_WORK)), &energy_t, w, &format!("W {joint} [J]"), color, width));
    }
    let force_t: Vec<i64> = match &run.contact_states {
        Some(s) => s.iter().map(|(t, _)| ns(*t)).collect(),
        None => run.constraints.iter().map(|(t, _)| ns(*t)).collect(),
    };
    for (c, contact) in run.contacts.iter().enumerate() {
        // contacts after the joints in the palette's order would repeat joint colours: start at
        // the far end
        let color = palette(PALETTE.len() - 1 - c % PALETTE.len());
        let cp = escape(&contact.name);
        out.extend(series(format!("{}/{cp}", paths.signal(NORMAL_FORCE)), &force_t, f_n[c].clone(), &format!("{} f_n [N]", contact.name), color, width));
        if let Some(ft) = f_t.get(c).filter(|v| !v.is_empty()) {
            let mag = ft.chunks(2).map(|p| (p[0] * p[0] + p[1] * p[1]).sqrt()).collect();
            out.extend(series(format!("{}/{cp}", paths.signal(FRICTION_FORCE)), &force_t, mag, &format!("{} |f_t| [N]", contact.name), color, width));
        }
        if let (Some(states), Some(ft)) = (&run.contact_states, f_t.get(c).filter(|v| !v.is_empty())) {
            let slip = states
                .iter()
                .map(|(_, s)| {
                    let (a, b) = (s.slip_velocity_t1.get(c).copied().unwrap_or(0.0), s.slip_velocity_t2.get(c).copied().unwrap_or(0.0));
                    (a * a + b * b).sqrt()
                })
                .collect();
            out.extend(series(format!("{}/{cp}", paths.signal(SLIP_SPEED)), &force_t, slip, &format!("{} |v_t| [m/s]", contact.name), color, width));
            if let Some(mu) = contact.friction.filter(|m| *m > 0.0) {
                let (t, v): (Vec<i64>, Vec<f64>) = ft
                    .chunks(2)
                    .zip(&f_n[c])
                    .zip(&force_t)
                    .filter(|((_, n), _)| **n > 0.0)
                    .map(|((p, n), t)| (*t, (p[0] * p[0] + p[1] * p[1]).sqrt() / (mu * n)))
                    .unzip();
                out.extend(series(format!("{}/{cp}", paths.signal(FRICTION_RATIO)), &t, v, &format!("{} |f_t|/(μ f_n)", contact.name), color, width));
            }
        }
        if let Some(m) = modes {
            let v = m[c].iter().map(|&x| f64::from(x)).collect();
            out.extend(series(
                format!("{}/{cp}", paths.signal(CONTACT_MODE)),
                &force_t,
                v,
                // short: the plot's title gives the codes (the long name made a legend that covered the data)
                &format!("{} mode", contact.name),
                color,
                width,
            ));
        }
    }
    // totals and the residual: `/energy_J/<term>[/<run>]`
    let term_path = |term: &str| match &paths.run {
        Some(r) => format!("/{ENERGY}/{term}/{}", escape(r)),
        None => format!("/{ENERGY}/{term}"),
    };
    for (k, (term, label, get)) in ENERGY_TERMS.iter().enumerate() {
        let v = run.energy.iter().map(|(_, e)| get(e)).collect();
        let name = match &paths.run {
            Some(r) => format!("{r}: {label} [J]"),
            None => format!("{label} [J]"),
        };
        let color = if paths.run.is_some() { palette(paths.index) } else { palette(k) };
        out.extend(series(term_path(term), &energy_t, v, &name, color, width));
    }
    let residual = run.energy.iter().map(|(_, e)| e.balance_residual).collect();
    let name = match &paths.run {
        Some(r) => format!("{r}: balance residual [J]"),
        None => "balance residual E − (ΔT + ΔV + ΔL i²/2 + losses) [J]".to_string(),
    };
    let color = if paths.run.is_some() { palette(paths.index) } else { rgba(90, 90, 90, 255) };
    out.extend(series(paths.signal(RESIDUAL), &energy_t, residual, &name, color, width));
    out
}

