//! Aligned text tables in sections, for people: as wide as they come (a file, a pipe), or fitted
//! to a width (a terminal's: [`TextTable::fitted`], titles and findings wrapped).

use super::text::wrap;
use super::{contacts, joints, TextTable};
use crate::compare::{Comparison, Ratios};
use crate::metrics::RunMetrics;

/// One section: a title over a [`TextTable`].
struct Table {
    title: String,
    table: TextTable,
}

impl Table {
    fn new(title: impl Into<String>, head: &[&str]) -> Self {
        Self { title: title.into(), table: TextTable::new(head) }
    }

    /// As aligned text (fitted to `width` columns when given), or (`markdown`) as a heading and
    /// a GitHub pipe table.
    fn write(&self, out: &mut String, markdown: bool, width: Option<usize>) {
        if markdown {
            out.push_str(&format!("### {}\n\n{}\n", self.title, self.table.markdown()));
        } else if let Some(w) = width {
            out.push_str(&format!("{}{}\n", wrap(&self.title, w, "", ""), self.table.fitted(w)));
        } else {
            out.push_str(&format!("{}\n{}\n", self.title, self.table.aligned()));
        }
    }
}

/// `x` with `d` decimals; in scientific notation with `d` significant decimals from 1e6 on
/// (a fixed-point 4e302 would be a 307-character cell), and `—` when it is not a finite number
/// (no table prints `inf` or `NaN`).
pub(super) fn f(x: f64, d: usize) -> String {
    if !x.is_finite() {
        ABSENT.into()
    } else if x.abs() >= 1e6 {
        format!("{x:.d$e}")
    } else {
        format!("{x:.d$}")
    }
}

/// The cell of a number a run does not have (it failed before its first sample).
pub(super) const ABSENT: &str = "—";

/// [`f`] of a number a run may not have: `—` when it has none.
pub(super) fn fo(x: Option<f64>, d: usize) -> String {
    x.map_or(ABSENT.into(), |x| f(x, d))
}

/// In mm with 3 decimals, from m.
pub(super) fn mm(x_m: f64) -> String {
    f(x_m * 1e3, 3)
}

/// Scientific with 2 decimals (`—` when not finite).
fn e(x: f64) -> String {
    if x.is_finite() {
        format!("{x:.2e}")
    } else {
        ABSENT.into()
    }
}

/// A ratio with 3 decimals, `-` when it does not exist.
pub(super) fn q(x: Option<f64>) -> String {
    x.filter(|x| x.is_finite()).map_or("-".into(), |x| f(x, 3))
}

/// The sections as aligned text (fitted to `width` columns when given), or (`markdown`) as
/// Markdown headings and pipe tables.
pub(super) fn render(runs: &[&RunMetrics], cmp: Option<&Comparison>, markdown: bool, width: Option<usize>) -> String {
    let ratios: Option<Vec<&Ratios>> = cmp.map(|c| c.runs.iter().map(|r| &r.to_baseline).collect());
    let base = cmp.map(|c| c.baseline_index);
    let labels = super::run_labels(runs);
    let left_out = |k: usize| cmp.is_some_and(|c| c.runs[k].not_compared.is_some());
    let name = |k: usize| {
        let r = &labels[k];
        if Some(k) == base {
            format!("{r} *")
        } else if left_out(k) {
            format!("{r} †")
        } else {
            r.clone()
        }
    };
    let mut out = String::new();

    // runs
    let any_left_out = (0..runs.len()).any(left_out);
    let title = if any_left_out {
        "Runs (* = baseline; ratios are run / baseline; † = not compared: no ratios, not ranked, the findings say why; \
         — = a number the run does not have)"
    } else if cmp.is_some() {
        "Runs (* = baseline; ratios are run / baseline)"
    } else if runs.iter().any(|r| !r.measured()) {
        "Runs (— = a number the run does not have: it failed before its first sample)"
    } else {
        "Runs"
    };
    let mut t = Table::new(
        title,
        &[
            "run",
            "scene",
            "contacts",
            "status",
            "t_end [s]",
            "samples",
            "peak |i| [A]",
            "at joint",
        ],
    );
    t.table.left = 4;
    for (k, r) in runs.iter().enumerate() {
        let contacts = if r.contacts.is_empty() {
            "-".to_string()
        } else {
            r.contacts.join(",")
        };
        let at = r
            .error_time_s
            .map_or(String::new(), |t| format!(" at {t:.3} s"));
        let (peak, joint) = r
            .peak_current
            .as_ref()
            .map_or(("-".into(), "-".into()), |p| {
                (f(p.current_a, 3), p.joint.clone())
            });
        let st = format!("{}{at}", r.status_text());
        t.table.rows.push(vec![
            name(k),
            r.scene.clone(),
            contacts,
            st,
            fo(r.t_end_s, 3),
            r.samples.to_string(),
            peak,
            joint,
        ]);
    }
    t.write(&mut out, markdown, width);

    // hand error
    let mut head = vec![
        "run",
        "x rms [mm]",
        "y rms [mm]",
        "z rms [mm]",
        "|e| rms [mm]",
        "x max [mm]",
        "y max [mm]",
        "z max [mm]",
        "|e| max [mm]",
    ];
    if cmp.is_some() {
        head.extend(["z rms / base", "|e| rms / base"]);
    }
    let mut t = Table::new("Hand error r - r_d", &head);
    for (k, r) in runs.iter().enumerate() {
        let mut row = vec![name(k)];
        match &r.hand_error {
            Some(h) => {
                row.extend([&h.x, &h.y, &h.z, &h.norm].map(|a| mm(a.rms_m)));
                row.extend([&h.x, &h.y, &h.z, &h.norm].map(|a| mm(a.max_abs_m)));
            }
            None => row.extend([ABSENT; 8].map(String::from)),
        }
        if let Some(q_) = &ratios {
            row.extend([q(q_[k].error_z_rms), q(q_[k].error_norm_rms)]);
        }
        t.table.rows.push(row);
    }
    t.write(&mut out, markdown, width);

    // energy totals
    // (the supply's columns only when a run models its supply: issue 26; the paper's table
    // is unchanged)
    let supply = runs.iter().any(|r| r.supply_energy_j().is_some());
    let mut head = vec!["run", "E = Σ ∫ i v dt [J]", "W = Σ ∫ τ q' dt [J]"];
    if supply {
        head.extend(["E_supply [J]", "regenerated [J]", "dumped [J]"]);
    }
    if cmp.is_some() {
        head.extend(["E / E_base", "W / W_base"]);
    }
    let mut t = Table::new("Energy totals at t_end", &head);
    for (k, r) in runs.iter().enumerate() {
        let mut row = vec![
            name(k),
            fo(r.electric_energy_total_j, 4),
            fo(r.link_work_total_j, 4),
        ];
        if supply {
            row.extend([r.supply_energy_j(), r.supply_regenerated_j(), r.supply_dumped_j()].map(|x| fo(x, 4)));
        }
        if let Some(q_) = &ratios {
            row.extend([q(q_[k].electric_energy), q(q_[k].link_work)]);
        }
        t.table.rows.push(row);
    }
    t.write(&mut out, markdown, width);

    // per-link energy
    let mut head: Vec<String> = vec!["joint".into()];
    head.extend(labels.iter().map(|r| format!("W {r} [J]")));
    head.extend(labels.iter().map(|r| format!("E {r} [J]")));
    if cmp.is_some() {
        head.extend(
            labels
                .iter()
                .enumerate()
                .filter(|&(k, _)| Some(k) != base)
                .map(|(_, r)| format!("E/E_base {r}")),
        );
    }
    let head: Vec<&str> = head.iter().map(String::as_str).collect();
    let mut t = Table::new(
        "Per-link energy at t_end (W_j work on the link, E_j electric energy of its motor)",
        &head,
    );
    for j in joints(runs) {
        let links: Vec<_> = runs
            .iter()
            .map(|r| r.links.iter().find(|l| l.joint == j))
            .collect();
        let mut row = vec![j.to_string()];
        row.extend(
            links
                .iter()
                .map(|l| l.map_or("-".into(), |l| f(l.work_j, 4))),
        );
        row.extend(
            links
                .iter()
                .map(|l| l.map_or("-".into(), |l| f(l.electric_energy_j, 4))),
        );
        if let Some(c) = cmp {
            let cells = c.links.iter().find(|l| l.joint == j).map(|l| &l.runs);
            for k in (0..runs.len()).filter(|&k| Some(k) != base) {
                let cell = cells.and_then(|c| c[k].as_ref());
                row.push(q(cell.and_then(|c| c.electric_energy_ratio)));
            }
        }
        t.table.rows.push(row);
    }
    t.write(&mut out, markdown, width);

    // contacts
    if !contacts(runs).is_empty() {
        let opening = runs.iter().any(|r| r.contact_states.iter().any(|c| c.model.as_deref() != Some("bilateral")));
        let mut t = Table::new(
            if opening {
                "Contacts (f_n < 0: the table pulls; max |C|, |C'|: how far a held contact drifts, - for a unilateral or \
                 compliant contact, whose gap opens: see the contact states)"
            } else {
                "Contacts (f_n < 0: the table pulls)"
            },
            &[
                "run",
                "contact",
                "min f_n [N]",
                "at [s]",
                "f_n < 0 for [s]",
                "first f_n < 0 [s]",
                "max |C| [m]",
                "max |C'| [m/s]",
            ],
        );
        t.table.left = 2;
        for (k, r) in runs.iter().enumerate() {
            for c in &r.contact_forces {
                let first = c.first_pull_s.map_or("-".into(), |t| f(t, 3));
                // a unilateral or compliant contact's |C| is its gap when open, not a drift
                let opens = r.contact_states.iter().any(|s| s.contact == c.contact && s.model.as_deref() != Some("bilateral"));
                let drift = |x: f64| if opens { "-".to_string() } else { e(x) };
                t.table.rows.push(vec![
                    name(k),
                    c.contact.clone(),
                    f(c.min_normal_force_n, 3),
                    f(c.t_min_normal_force_s, 3),
                    f(c.pull_time_s, 3),
                    first,
                    drift(c.max_abs_position_m),
                    drift(c.max_abs_velocity_m_s),
                ]);
            }
        }
        t.write(&mut out, markdown, width);
    }

    // contact models (runs with `/contacts`)
    if runs.iter().any(|r| !r.contact_states.is_empty()) {
        let mut t = Table::new(
            "Contact states (unilateral and compliant contacts: time in contact, events, losses; \
             μ to stick = max |f_t|/f_n over the sticking samples, in contact = over every sample in contact)",
            &[
                "run",
                "contact",
                "model",
                "μ",
                "in contact [s]",
                "lift-offs",
                "touch-downs",
                "impacts",
                "rests",
                "stick→slip",
                "slip→stick",
                "impact loss [J]",
                "friction work [J]",
                "damping loss [J]",
                "μ to stick",
                "μ in contact",
                "f_n min [N]",
                "f_n max [N]",
            ],
        );
        t.table.left = 3;
        for (k, r) in runs.iter().enumerate() {
            for c in &r.contact_states {
                let ev = &c.events;
                t.table.rows.push(vec![
                    name(k),
                    c.contact.clone(),
                    c.model.clone().unwrap_or_else(|| "-".into()),
                    c.friction.map_or("-".into(), |m| f(m, 3)),
                    f(c.time_in_contact_s, 4),
                    ev.lift_offs.to_string(),
                    ev.touch_downs.to_string(),
                    ev.impacts.to_string(),
                    ev.rests.to_string(),
                    ev.stick_to_slip.to_string(),
                    ev.slip_to_stick.to_string(),
                    e(c.impact_loss_j),
                    e(c.friction_work_j),
                    e(c.damping_loss_j),
                    q(c.stick_friction_needed),
                    q(c.contact_friction_needed),
                    c.min_normal_force_in_contact_n.map_or("-".into(), |x| f(x, 3)),
                    c.max_normal_force_in_contact_n.map_or("-".into(), |x| f(x, 3)),
                ]);
            }
        }
        t.write(&mut out, markdown, width);
    }

    // the contact audit (runs with `/contacts`): each law's worst value over the run and the
    // samples beyond its bound ([`schemas::ContactAuditor`])
    if runs.iter().any(|r| r.contact_audit.is_some()) {
        let bounds = runs.iter().find_map(|r| r.contact_audit.as_ref()).map(|a| a.audit.bounds).expect("some run has an audit");
        let mut t = Table::new(
            &format!(
                "Contact laws at every sample (worst value; bounds: closed |g| {:.0e} m, |ġ| {:.0e} m/s, force {:.0e} N, slip angle {:.0e} rad; \
                 breaches = samples beyond a bound, 0 when every law held)",
                bounds.gap_m, bounds.gap_rate_m_s, bounds.force_n, bounds.angle_rad
            ),
            &["run", "contact", "closed |g| [m]", "closed |ġ| [m/s]", "inside while open [m]", "pull [N]", "|f| while open [N]", "outside cone [N]", "∠(−f_t, v_t) [rad]", "breaches"],
        );
        t.table.left = 2;
        for (k, r) in runs.iter().enumerate() {
            let Some(a) = &r.contact_audit else { continue };
            for c in a.audit.contacts.iter().filter(|c| c.model != "bilateral") {
                let mut row = vec![name(k), c.contact.clone()];
                row.extend(c.laws(&a.audit.bounds).iter().map(|l| e(l.2.value)));
                row.push(c.breaches().to_string());
                t.table.rows.push(row);
            }
        }
        t.write(&mut out, markdown, width);
    }

    // energy balance
    // the report explains the balance in its own section (report.rs)
    if !markdown {
        // runs with unilateral or compliant contacts lose energy in them too (impacts,
        // friction, compliant damping): a column of their own, only when some run has them,
        // so that every row adds up (a bilateral comparison prints as before)
        let contact_losses = |r: &RunMetrics| -> f64 { r.contact_states.iter().map(|c| c.impact_loss_j + c.friction_work_j + c.damping_loss_j).sum() };
        let with_contacts = runs.iter().any(|r| !r.contact_states.is_empty());
        let title = if with_contacts {
            "Energy balance at t_end [J]: E = ΔT + ΔV + Δ(L i²/2) + R loss + D loss + D_m loss + contact losses + residual \
             (R: windings, D: joints, D_m: gears; contact: impacts, friction and compliant damping, with ½ k δ² of a \
             compliant contact pressed at t_end in the residual; - where a recording has only D + D_m)"
        } else {
            "Energy balance at t_end [J]: E = ΔT + ΔV + Δ(L i²/2) + R loss + D loss + D_m loss + residual \
             (R: windings, D: joints, D_m: gears; - where a recording has only D + D_m)"
        };
        let mut head = vec!["run", "E", "ΔT", "ΔV", "Δ(L i²/2)", "R loss", "D loss", "D_m loss", "D + D_m"];
        if with_contacts {
            head.push("contact losses");
        }
        head.extend(["residual", "max |residual|", "max |res| / E"]);
        let mut t = Table::new(title, &head);
        for (k, r) in runs.iter().enumerate() {
            let Some(a) = &r.energy else {
                t.table.rows.push(std::iter::once(name(k)).chain((1..head.len()).map(|_| ABSENT.to_string())).collect());
                continue;
            };
            let rel = a.max_abs_residual_rel.map_or("-".into(), e);
            let mut row = vec![
                name(k),
                f(a.electric_j, 4),
                f(a.kinetic_change_j, 4),
                f(a.potential_change_j, 4),
                f(a.magnetic_change_j, 4),
                f(a.resistive_loss_j, 4),
                a.gear_friction_loss_j.map_or("-".into(), |g| f(a.friction_loss_j - g, 4)),
                a.gear_friction_loss_j.map_or("-".into(), |g| f(g, 4)),
                f(a.friction_loss_j, 4),
            ];
            if with_contacts {
                row.push(if r.contact_states.is_empty() { "-".into() } else { f(contact_losses(r), 4) });
            }
            row.extend([e(a.residual_j), e(a.max_abs_residual_j), rel]);
            t.table.rows.push(row);
        }
        t.write(&mut out, markdown, width);
    }

    // findings
    if let Some(c) = cmp.filter(|_| !markdown) {
        out.push_str("Findings\n");
        for s in &c.findings {
            match width {
                Some(w) => out.push_str(&wrap(s, w, "- ", "  ")),
                None => out.push_str(&format!("- {s}\n")),
            }
        }
    }
    while out.ends_with("\n\n") {
        out.pop();
    }
    out
}
