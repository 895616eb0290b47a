use super::input::{csv_rows, from_csv};
use super::*;

#[test]
fn tolerance_is_symmetric_and_nan_aware() {
    let t = Tolerance::default();
    assert!(t.close(1.0, 1.0 + 5e-10) && t.close(1.0 + 5e-10, 1.0));
    assert!(!t.close(1.0, 1.01) && !t.close(0.0, 1e-11));
    assert!(t.close(f64::NAN, f64::NAN) && !t.close(f64::NAN, 1.0));
    assert!(t.close(f64::INFINITY, f64::INFINITY) && !t.close(f64::INFINITY, 1.0));
}

#[test]
fn csv_rows_follow_rfc_4180() {
    let rows = csv_rows("a,\"b,\"\"c\"\"\",d\r\n\"x\ny\",,z\n").unwrap();
    assert_eq!(rows, [vec!["a", "b,\"c\"", "d"], vec!["x\ny", "", "z"]]);
}

/// Tables of this version and of older ones (units upper case, no dot before an item) read
/// the same.
#[test]
fn csv_columns_map_to_quantities() {
    let old = "run,file,E_total_J,W_total_J,W_j1_J,E_j1_J,E_j1_ratio,fn_min_elbow_4_N,\
               first_pull_elbow_4_s,pull_elbow_4_s\nr,f.mcap,3,2,1,NaN,,-1,,0.5\n";
    let new = "run,file,E_total_j,W_total_j,W.j1_j,E.j1_j,E.j1_ratio,fn_min.elbow_4_n,\
               first_pull.elbow_4_s,pull.elbow_4_s\nr,f.mcap,3,2,1,NaN,,-1,,0.5\n";
    let (runs, runs_new) = (from_csv(old).unwrap(), from_csv(new).unwrap());
    assert_eq!(format!("{:?}", runs[0].values), format!("{:?}", runs_new[0].values));
    let got: Vec<(&str, Option<&str>, f64)> = runs[0]
        .values
        .iter()
        .map(|(k, i, x)| (KINDS[*k].id, i.as_deref(), *x))
        .collect();
    assert_eq!(got.len(), 6);
    assert_eq!(got[0], ("electric_energy_total_j", None, 3.0));
    assert_eq!(got[2], ("work_j", Some("j1"), 1.0));
    assert!(got[3].2.is_nan() && got[3].1 == Some("j1"));
    assert_eq!(got[4], ("min_normal_force_n", Some("elbow_4"), -1.0));
    assert_eq!(got[5], ("pull_time_s", Some("elbow_4"), 0.5));
    let peak = KINDS.iter().position(|k| k.id == "peak_current_a").unwrap();
    assert!(!runs[0].carried[peak]);
}
