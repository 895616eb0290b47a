//! The summary as one polars DataFrame and the query on it (feature `tables`).

use polars::prelude::*;

use super::{Filter, Op, Query, SummaryRow};
use crate::metrics::RunMetrics;

/// One DataFrame, one row per entry of `rows`: [`BASE_COLUMNS`] (`min_normal_force_n`: the lowest
/// over the contacts, `pull_time_s`: the longest; both null without contacts), then `error`, `bytes`,
/// `E_supply_j`, `supply_regenerated_j`, `supply_dumped_j` when some run has a supply, then
/// `E.<joint>_j` and `W.<joint>_j` for every joint of any run (null where a run has no such
/// joint), then for every contact with a contact model in any run (`/contacts`)
/// `in_contact.<c>_s`, `lift_offs.<c>`, `impacts.<c>`, `impact_loss.<c>_j`, `friction_work.<c>_j`,
/// `damping_loss.<c>_j`, `mu_stick.<c>_ratio` (null where a run has no such contact), then
/// `p.<param>` for each of `params` (Float64 when every value is a number, else
/// text).
pub fn summary_frame(rows: &[SummaryRow], params: &[String]) -> PolarsResult<DataFrame> {
    let n = rows.len();
    // a number a run does not have (it failed before its first sample) or that is not finite
    // is null, never a made-up value
    let m = |f: &dyn Fn(&RunMetrics) -> Option<f64>| -> Vec<Option<f64>> { rows.iter().map(|r| f(&r.metrics).filter(|x| x.is_finite())).collect() };
    let s = |f: &dyn Fn(&SummaryRow) -> Option<String>| -> Vec<Option<String>> { rows.iter().map(f).collect() };
    let min_force = |r: &RunMetrics| -> Option<f64> {
        r.contact_forces.iter().map(|c| c.min_normal_force_n).reduce(f64::min)
    };
    let mut cols = vec![
        Column::new("file".into(), s(&|r| Some(r.metrics.file.clone()))),
        Column::new("scene".into(), s(&|r| Some(r.metrics.scene.clone()))),
        Column::new("run".into(), s(&|r| Some(r.metrics.run.clone()))),
        Column::new("status".into(), s(&|r| Some(r.metrics.status_text()))),
        Column::new("contacts".into(), s(&|r| Some(r.metrics.contacts.join(",")))),
        Column::new("n_contacts".into(), rows.iter().map(|r| r.metrics.contacts.len() as u32).collect::<Vec<_>>()),
        Column::new("integrator".into(), s(&|r| r.integrator.clone())),
        Column::new("t_end_s".into(), m(&|r| r.t_end_s)),
        Column::new("samples".into(), rows.iter().map(|r| r.metrics.samples as u64).collect::<Vec<_>>()),
        Column::new("err_norm_rms_m".into(), m(&|r| r.hand_error.as_ref().map(|h| h.norm.rms_m))),
        Column::new("err_norm_max_m".into(), m(&|r| r.hand_error.as_ref().map(|h| h.norm.max_abs_m))),
        Column::new("err_z_rms_m".into(), m(&|r| r.hand_error.as_ref().map(|h| h.z.rms_m))),
        Column::new("err_z_max_m".into(), m(&|r| r.hand_error.as_ref().map(|h| h.z.max_abs_m))),
        Column::new("E_total_j".into(), m(&|r| r.electric_energy_total_j)),
        Column::new("W_total_j".into(), m(&|r| r.link_work_total_j)),
        Column::new(
            "peak_current_a".into(),
            rows.iter().map(|r| r.metrics.peak_current.as_ref().map(|p| p.current_a)).collect::<Vec<_>>(),
        ),
        Column::new("peak_current_joint".into(), s(&|r| r.metrics.peak_current.as_ref().map(|p| p.joint.clone()))),
        Column::new("fn_min_n".into(), rows.iter().map(|r| min_force(&r.metrics)).collect::<Vec<_>>()),
        Column::new(
            "pull_max_s".into(),
            rows.iter()
                .map(|r| r.metrics.contact_forces.iter().map(|c| c.pull_time_s).reduce(f64::max))
                .collect::<Vec<_>>(),
        ),
        Column::new(
            "residual_max_rel".into(),
            m(&|r| r.energy.as_ref().and_then(|e| e.max_abs_residual_rel)),
        ),
        Column::new("error".into(), s(&|r| r.metrics.error.clone())),
        Column::new("bytes".into(), rows.iter().map(|r| r.bytes).collect::<Vec<_>>()),
    ];
    // per-link columns over the union of joints, in first-seen order
    let mut joints: Vec<&str> = Vec::new();
    for r in rows {
        for l in &r.metrics.links {
            if !joints.contains(&l.joint.as_str()) {
                joints.push(&l.joint);
            }
        }
    }
    let link = |joint: &str, f: fn(&crate::metrics::LinkMetrics) -> f64| -> Vec<Option<f64>> {
        rows.iter()
            .map(|r| r.metrics.links.iter().find(|l| l.joint == joint).map(f))
            .collect()
    };
    // the energy the supply delivered, regenerated and dumped (issue 26), when some run
    // models its supply (null for the others)
    if rows.iter().any(|r| r.metrics.supply_energy_j().is_some()) {
        cols.push(Column::new("E_supply_j".into(), m(&|r| r.supply_energy_j())));
        cols.push(Column::new("supply_regenerated_j".into(), m(&|r| r.supply_regenerated_j())));
        cols.push(Column::new("supply_dumped_j".into(), m(&|r| r.supply_dumped_j())));
    }
    for j in &joints {
        cols.push(Column::new(format!("E.{j}_j").into(), link(j, |l| l.electric_energy_j)));
    }
    for j in &joints {
        cols.push(Column::new(format!("W.{j}_j").into(), link(j, |l| l.work_j)));
    }
    // per contact with a contact model (`/contacts`) in some run, in first-seen order
    let mut states: Vec<&str> = Vec::new();
    for r in rows {
        for c in &r.metrics.contact_states {
            if !states.contains(&c.contact.as_str()) {
                states.push(&c.contact);
            }
        }
    }
    type StateFn = fn(&crate::metrics::ContactStateMetrics) -> Option<f64>;
    let state_columns: [(&str, &str, StateFn); 7] = [
        ("in_contact", "_s", |c| Some(c.time_in_contact_s)),
        ("lift_offs", "", |c| Some(c.events.lift_offs as f64)),
        ("impacts", "", |c| Some(c.events.impacts as f64)),
        ("impact_loss", "_j", |c| Some(c.impact_loss_j)),
        ("friction_work", "_j", |c| Some(c.friction_work_j)),
        ("damping_loss", "_j", |c| Some(c.damping_loss_j)),
        ("mu_stick", "_ratio", |c| c.stick_friction_needed),
    ];
    for c in &states {
        for (quantity, unit, f) in state_columns {
            let values: Vec<Option<f64>> = rows.iter().map(|r| r.metrics.contact_states.iter().find(|s| s.contact == *c).and_then(f)).collect();
            cols.push(Column::new(format!("{quantity}.{c}{unit}").into(), values));
        }
    }
    for (k, p) in params.iter().enumerate() {
        let values: Vec<Option<&serde_json::Value>> = rows.iter().map(|r| r.params[k].as_ref()).collect();
        let name = format!("p.{p}");
        let numeric = values.iter().all(|v| v.is_none_or(|v| v.is_number()));
        cols.push(if numeric {
            Column::new(name.into(), values.iter().map(|v| v.and_then(|v| v.as_f64())).collect::<Vec<_>>())
        } else {
            let text = |v: &serde_json::Value| v.as_str().map_or_else(|| v.to_string(), String::from);
            Column::new(name.into(), values.iter().map(|v| v.map(text)).collect::<Vec<_>>())
        });
    }
    DataFrame::new(n, cols)
}

impl Query {
    /// Runs the query on `df` with polars' eager API (filter masks, a stable multi-column sort,
    /// a projection and a head): on a table of one row per recording there is nothing for a
    /// query planner to gain. Errors name the unknown column or the value that does not parse
    /// as a number for a numeric column.
    pub fn run(&self, mut df: DataFrame) -> Result<DataFrame, String> {
        let known = |df: &DataFrame, c: &str| -> Result<(), String> {
            match df.column(c) {
                Ok(_) => Ok(()),
                Err(_) => Err(format!("no column {c:?}; the columns are: {}", df.get_column_names().iter().map(|c| c.as_str()).collect::<Vec<_>>().join(", "))),
            }
        };
        for f in &self.filters {
            known(&df, &f.column)?;
            let mask = filter_mask(df.column(&f.column).map_err(|e| e.to_string())?, f)?;
            df = df.filter(&mask).map_err(|e| e.to_string())?;
        }
        if !self.sort.is_empty() {
            for c in &self.sort {
                known(&df, c)?;
            }
            let opts = SortMultipleOptions::default()
                .with_order_descending(self.descending)
                .with_nulls_last(true)
                .with_maintain_order(true);
            df = df.sort(self.sort.iter().map(String::as_str).collect::<Vec<_>>(), opts).map_err(|e| e.to_string())?;
        }
        if !self.columns.is_empty() {
            for c in &self.columns {
                known(&df, c)?;
            }
            df = df.select(self.columns.iter().map(String::as_str)).map_err(|e| e.to_string())?;
        }
        if let Some(n) = self.limit {
            df = df.head(Some(n));
        }
        Ok(df)
    }
}

/// `v OP x` per row (null where `v` is null).
fn compare<C, R: Copy>(v: &C, x: R, op: Op) -> BooleanChunked
where
    C: ChunkCompareEq<R, Item = BooleanChunked> + ChunkCompareIneq<R, Item = BooleanChunked>,
{
    match op {
        Op::Eq => v.equal(x),
        Op::Ne => v.not_equal(x),
        Op::Lt => v.lt(x),
        Op::Le => v.lt_eq(x),
        Op::Gt => v.gt(x),
        Op::Ge => v.gt_eq(x),
    }
}

/// The rows of `column` where `f` holds (a null never does): numbers compare as numbers, text
/// as text.
fn filter_mask(column: &Column, f: &Filter) -> Result<BooleanChunked, String> {
    let s = column.as_materialized_series();
    let mask = if s.dtype().is_primitive_numeric() {
        let x: f64 = f.value.parse().map_err(|_| format!("filter {:?}: {:?} is not a number (the column is numeric)", f.column, f.value))?;
        let s = s.cast(&DataType::Float64).map_err(|e| e.to_string())?;
        compare(s.f64().map_err(|e| e.to_string())?, x, f.op)
    } else {
        let s = s.cast(&DataType::String).map_err(|e| e.to_string())?;
        compare(s.str().map_err(|e| e.to_string())?, f.value.as_str(), f.op)
    };
    // a null compares as null: not kept
    mask.fill_null_with_values(false).map_err(|e| e.to_string())
}


#[cfg(test)]
mod tests {
    use super::*;

    /// The synthetic unilateral run and a bilateral one: 7 columns per contact with a contact
    /// model, the unilateral run's values, nulls for the bilateral run.
    #[test]
    fn contact_state_columns() {
        let dir = tempfile::tempdir().unwrap();
        let (s, _) = schemas::synth::unilateral();
        let uni = crate::metrics::read_run_metrics(&s.write_in(dir.path())).unwrap();
        let plain = crate::compare::tests::paper_runs().remove(0);
        let row = |metrics: RunMetrics| SummaryRow { metrics, bytes: 0, integrator: None, params: vec![] };
        let df = summary_frame(&[row(plain.clone()), row(uni.clone())], &[]).unwrap();
        let only = summary_frame(&[row(plain)], &[]).unwrap();
        assert_eq!(df.width(), only.width() + 2 * 7);
        let get = |name: &str| df.column(name).unwrap().f64().unwrap().get(1);
        assert_eq!(get("in_contact.elbow4_s"), Some(uni.contact_states[0].time_in_contact_s));
        assert_eq!(get("impacts.elbow4"), Some(1.0));
        assert_eq!(get("mu_stick.elbow7_ratio"), Some(0.25));
        assert_eq!(df.column("impacts.elbow4").unwrap().f64().unwrap().get(0), None);
    }
}
