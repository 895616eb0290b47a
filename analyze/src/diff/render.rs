//! Rendering a [`Diff`] for people (table) and machines (JSON, CSV).

use super::*;
use crate::render::Format;
use crate::Error;

/// Renders a diff. Table: the differences (moved, missing) first, or every quantity with
/// `all`, then the counts and a final line `N quantities moved beyond rtol …, atol …` or
/// `no differences beyond rtol …, atol …`. JSON: the whole [`Diff`]. CSV: one row per
/// quantity (every one).
pub fn render_diff(d: &Diff, format: Format, all: bool) -> Result<String, Error> {
    let num = |x: Option<f64>, p: usize| x.map_or("-".to_string(), |x| format!("{x:.p$e}"));
    Ok(match format {
        Format::Json => serde_json::to_string_pretty(d)? + "\n",
        Format::Csv => {
            let mut out =
                String::from("run,quantity,joint,contact,unit,a,b,diff,abs_diff,rel_diff,status\n");
            let cell = |x: Option<f64>| x.map_or(String::new(), |x| x.to_string());
            let quote = |s: &str| {
                if s.contains([',', '"', '\n', '\r']) {
                    format!("\"{}\"", s.replace('"', "\"\""))
                } else {
                    s.to_string()
                }
            };
            for q in &d.quantities {
                let cells = [
                    quote(&q.run),
                    q.quantity.clone(),
                    quote(q.joint.as_deref().unwrap_or("")),
                    quote(q.contact.as_deref().unwrap_or("")),
                    q.unit.clone(),
                    cell(q.a),
                    cell(q.b),
                    cell(q.diff),
                    cell(q.abs_diff),
                    cell(q.rel_diff),
                    q.status.as_str().replace(' ', "_"),
                ];
                out += &(cells.join(",") + "\n");
            }
            out
        }
        Format::Table => {
            let mut out = format!("A: {} ({:?})\nB: {} ({:?})\n", d.a, d.a_kind, d.b, d.b_kind)
                .replace("(Recording)", "(recording)")
                .replace("(Json)", "(JSON table)")
                .replace("(Csv)", "(CSV table)");
            for p in d.runs.iter().filter(|p| p.run_a != p.run_b) {
                out += &format!(
                    "run {:?} of A compared with run {:?} of B (the only run of each)\n",
                    p.run_a, p.run_b
                );
            }
            for (side, runs) in [("A", &d.only_in_a), ("B", &d.only_in_b)] {
                if !runs.is_empty() {
                    out += &format!("runs only in {side}: {}\n", runs.join(", "));
                }
            }
            out.push('\n');
            let shown: Vec<&QuantityDiff> = d
                .quantities
                .iter()
                .filter(|q| all || q.status.differs())
                .collect();
            if !shown.is_empty() {
                let head = [
                    "run",
                    "quantity",
                    "link/contact",
                    "A",
                    "B",
                    "B - A",
                    "rel",
                    "status",
                ];
                let rows: Vec<[String; 8]> = shown
                    .iter()
                    .map(|q| {
                        [
                            q.run.clone(),
                            format!("{} [{}]", q.label, q.unit),
                            q.joint.clone().or(q.contact.clone()).unwrap_or_default(),
                            num(q.a, 9),
                            num(q.b, 9),
                            num(q.diff, 3),
                            num(q.rel_diff, 2),
                            q.status.as_str().to_string(),
                        ]
                    })
                    .collect();
                let mut w: Vec<usize> = head.iter().map(|h| h.chars().count()).collect();
                for r in &rows {
                    for (c, s) in r.iter().enumerate() {
                        w[c] = w[c].max(s.chars().count());
                    }
                }
                let line = |cells: &[String]| {
                    let parts: Vec<String> = cells
                        .iter()
                        .enumerate()
                        .map(|(c, s)| {
                            let pad = " ".repeat(w[c] - s.chars().count());
                            if c < 3 || c == 7 {
                                format!("{s}{pad}")
                            } else {
                                format!("{pad}{s}")
                            }
                        })
                        .collect();
                    parts.join("  ").trim_end().to_string() + "\n"
                };
                out += &line(&head.map(String::from));
                out += &line(&w.iter().map(|&n| "-".repeat(n)).collect::<Vec<_>>());
                for r in &rows {
                    out += &line(r);
                }
                out.push('\n');
            }
            if !all && d.same > 0 {
                out += &format!(
                    "{} quantities within the tolerances (--all shows them)\n",
                    d.same
                );
            }
            if d.not_compared > 0 && d.common_only {
                out += &format!(
                    "{} quantities not compared (only one input's format carries them; --common-only)\n",
                    d.not_compared
                );
            }
            let tol = format!("rtol {:e}, atol {:e}", d.rtol, d.atol);
            if d.differs() {
                let mut what = vec![format!("{} quantities moved beyond {tol}", d.moved)];
                if d.missing > 0 {
                    what.push(format!("{} missing on one side", d.missing));
                }
                if d.not_compared > 0 && !d.common_only {
                    what.push(format!(
                        "{} carried by one input only (a table of another format or version, or with sections left out; --common-only compares the rest)",
                        d.not_compared
                    ));
                }
                let runs = d.only_in_a.len() + d.only_in_b.len();
                if runs > 0 {
                    what.push(format!("{runs} runs in one input only"));
                }
                out += &what.join("; ");
                out.push('\n');
            } else {
                out += &format!("no differences beyond {tol}\n");
            }
            out
        }
    })
}
