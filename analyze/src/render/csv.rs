//! CSV: one header row, one row per run (column names in the parent module's docs).

use super::{contacts, joints, status};
use crate::compare::{Comparison, Ratios};
use crate::metrics::RunMetrics;

/// One cell per column; `None` is an empty cell.
struct Row(Vec<Option<String>>);

impl Row {
    fn text(&mut self, s: &str) {
        self.0.push(Some(s.to_string()));
    }
    /// A number; an empty cell when it is not finite (a CSV never holds `inf` or `NaN`).
    fn num(&mut self, x: f64) {
        self.opt(Some(x));
    }
    /// A number, or an empty cell when the run does not have it.
    fn opt(&mut self, x: Option<f64>) {
        self.0.push(x.filter(|x| x.is_finite()).map(number));
    }
}

/// `x` in Rust's shortest round-trip form: positional from 1e-5 to 1e16 (as `Display`
/// writes it), scientific outside (`Display` would write 5e-324 as a 326-character decimal).
fn number(x: f64) -> String {
    if x == 0.0 || (1e-5..1e16).contains(&x.abs()) {
        x.to_string()
    } else {
        format!("{x:e}")
    }
}

/// The rows as CSV (RFC 4180 quoting by the `csv` crate).
fn csv_text(head: &[String], rows: &[Vec<String>]) -> String {
    let mut w = csv::WriterBuilder::new().flexible(true).from_writer(Vec::new());
    for r in std::iter::once(head).chain(rows.iter().map(Vec::as_slice)) {
        // writing into memory cannot fail
        let _ = w.write_record(r);
    }
    String::from_utf8(w.into_inner().unwrap_or_default()).unwrap_or_default()
}

pub(super) fn render(runs: &[&RunMetrics], cmp: Option<(&Comparison, &[&Ratios])>) -> String {
    let joints = joints(runs);
    let contacts = contacts(runs);
    let mut head: Vec<String> = [
        "run",
        "file",
        "scene",
        "status",
        "contacts",
        "n_contacts",
        "samples",
        "t_end_s",
        "error_time_s",
        "err_x_rms_m",
        "err_x_max_m",
        "err_y_rms_m",
        "err_y_max_m",
        "err_z_rms_m",
        "err_z_max_m",
        "err_norm_rms_m",
        "err_norm_max_m",
        "E_total_j",
        "W_total_j",
    ]
    .map(String::from)
    .to_vec();
    // the supply's energies (issue 26) only when a run models its supply: the paper's table
    // keeps its columns
    let supply = runs.iter().any(|r| r.supply_energy_j().is_some());
    if supply {
        head.extend(["E_supply_j", "supply_regenerated_j", "supply_dumped_j"].map(String::from));
    }
    if cmp.is_some() {
        head.extend(
            [
                "E_total_ratio",
                "W_total_ratio",
                "err_z_rms_ratio",
                "err_norm_rms_ratio",
            ]
            .map(String::from),
        );
    }
    head.extend(
        [
            "peak_current_a",
            "peak_current_joint",
            "dT_j",
            "dV_j",
            "dMagnetic_j",
            "resistive_loss_j",
            "friction_loss_j",
            "gear_friction_loss_j",
            "residual_j",
            "residual_max_abs_j",
            "residual_max_rel",
        ]
        .map(String::from),
    );
    for j in &joints {
        head.push(format!("W.{j}_j"));
        head.push(format!("E.{j}_j"));
        if cmp.is_some() {
            head.push(format!("E.{j}_ratio"));
        }
    }
    for c in &contacts {
        head.extend([
            format!("fn_min.{c}_n"),
            format!("pull.{c}_s"),
            format!("first_pull.{c}_s"),
        ]);
    }
    // contacts with a contact model in some run (`/contacts`): their states
    let states = super::union(runs.iter().flat_map(|r| r.contact_states.iter().map(|c| c.contact.as_str())));
    let last = cmp.map(|_| "not_compared".to_string());
    for c in &states {
        head.extend([
            format!("in_contact.{c}_s"),
            format!("lift_offs.{c}"),
            format!("touch_downs.{c}"),
            format!("impacts.{c}"),
            format!("rests.{c}"),
            format!("stick_to_slip.{c}"),
            format!("slip_to_stick.{c}"),
            format!("impact_loss.{c}_j"),
            format!("friction_work.{c}_j"),
            format!("damping_loss.{c}_j"),
            format!("mu_stick.{c}_ratio"),
            format!("mu_contact.{c}_ratio"),
            format!("fn_contact_min.{c}_n"),
            format!("fn_contact_max.{c}_n"),
        ]);
    }

    head.extend(last);
    let mut lines = Vec::with_capacity(runs.len());
    for (k, r) in runs.iter().enumerate() {
        let mut row = Row(Vec::with_capacity(64));
        for s in [
            &r.run,
            &r.file,
            &r.scene,
            status(r.status),
            &r.contacts.join(";"),
        ] {
            row.text(s);
        }
        row.num(r.contacts.len() as f64);
        row.num(r.samples as f64);
        row.opt(r.t_end_s);
        row.opt(r.error_time_s);
        let e = r.hand_error.as_ref();
        for a in [e.map(|e| &e.x), e.map(|e| &e.y), e.map(|e| &e.z), e.map(|e| &e.norm)] {
            row.opt(a.map(|a| a.rms_m));
            row.opt(a.map(|a| a.max_abs_m));
        }
        row.opt(r.electric_energy_total_j);
        row.opt(r.link_work_total_j);
        if supply {
            row.opt(r.supply_energy_j());
            row.opt(r.supply_regenerated_j());
            row.opt(r.supply_dumped_j());
        }
        if let Some((_, ratios)) = cmp {
            let q = ratios[k];
            for x in [
                q.electric_energy,
                q.link_work,
                q.error_z_rms,
                q.error_norm_rms,
            ] {
                row.opt(x);
            }
        }
        row.opt(r.peak_current.as_ref().map(|p| p.current_a));
        row.0.push(r.peak_current.as_ref().map(|p| p.joint.clone()));
        let a = r.energy.as_ref();
        for x in [
            a.map(|a| a.kinetic_change_j),
            a.map(|a| a.potential_change_j),
            a.map(|a| a.magnetic_change_j),
            a.map(|a| a.resistive_loss_j),
            a.map(|a| a.friction_loss_j),
        ] {
            row.opt(x);
        }
        row.opt(a.and_then(|a| a.gear_friction_loss_j));
        for x in [a.map(|a| a.residual_j), a.map(|a| a.max_abs_residual_j)] {
            row.opt(x);
        }
        row.opt(a.and_then(|a| a.max_abs_residual_rel));
        for j in &joints {
            let link = r.links.iter().find(|l| l.joint == *j);
            row.opt(link.map(|l| l.work_j));
            row.opt(link.map(|l| l.electric_energy_j));
            if let Some((c, _)) = cmp {
                let cell = c
                    .links
                    .iter()
                    .find(|l| l.joint == *j)
                    .and_then(|l| l.runs[k].as_ref());
                row.opt(cell.and_then(|c| c.electric_energy_ratio));
            }
        }
        for name in &contacts {
            let c = r.contact_forces.iter().find(|c| c.contact == *name);
            row.opt(c.map(|c| c.min_normal_force_n));
            row.opt(c.map(|c| c.pull_time_s));
            row.opt(c.and_then(|c| c.first_pull_s));
        }
        for name in &states {
            let c = r.contact_states.iter().find(|c| c.contact == *name);
            row.opt(c.map(|c| c.time_in_contact_s));
            let ev = c.map(|c| &c.events);
            for n in [
                ev.map(|e| e.lift_offs),
                ev.map(|e| e.touch_downs),
                ev.map(|e| e.impacts),
                ev.map(|e| e.rests),
                ev.map(|e| e.stick_to_slip),
                ev.map(|e| e.slip_to_stick),
            ] {
                row.opt(n.map(|n| n as f64));
            }
            row.opt(c.map(|c| c.impact_loss_j));
            row.opt(c.map(|c| c.friction_work_j));
            row.opt(c.map(|c| c.damping_loss_j));
            row.opt(c.and_then(|c| c.stick_friction_needed));
            row.opt(c.and_then(|c| c.contact_friction_needed));
            row.opt(c.and_then(|c| c.min_normal_force_in_contact_n));
            row.opt(c.and_then(|c| c.max_normal_force_in_contact_n));
        }
        if let Some((c, _)) = cmp {
            // why the run has no ratios (empty when it is compared)
            row.0.push(c.runs[k].not_compared.clone());
        }
        lines.push(row.0.into_iter().map(Option::unwrap_or_default).collect());
    }
    csv_text(&head, &lines)
}
