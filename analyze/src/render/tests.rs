//! Rendering: JSON round-trips, CSV shape, table alignment and content.

use super::*;
use crate::compare::tests::paper_runs;

/// The paper's three runs; two-elbow's elbow7 pulls, and one ratio does not exist.
fn comparison() -> Comparison {
    let mut runs = paper_runs();
    let c7 = &mut runs[0].contact_forces[1];
    (c7.pull_time_s, c7.first_pull_s, c7.min_normal_force_n) = (0.31, Some(0.2), -4.0);
    runs[2].links[2].electric_energy_j = 0.0; // baseline E_3 = 0: no E_3 ratios
    Comparison::new(&runs, None).unwrap()
}

#[test]
fn format_parses_and_displays() {
    assert_eq!("table".parse::<Format>(), Ok(Format::Table));
    assert_eq!(" JSON ".parse::<Format>(), Ok(Format::Json));
    assert_eq!("Csv".parse::<Format>(), Ok(Format::Csv));
    let err = "xml".parse::<Format>().unwrap_err().to_string();
    assert!(
        err.contains("\"xml\"") && err.contains("table, json or csv"),
        "{err}"
    );
    for f in Format::ALL {
        assert_eq!(f.to_string().parse::<Format>(), Ok(f));
    }
    assert_eq!(Format::default(), Format::Table);
}

#[test]
fn json_round_trips_through_serde_with_stable_keys() {
    let cmp = comparison();
    let text = render_comparison(&cmp, Format::Json).unwrap();
    assert_eq!(serde_json::from_str::<Comparison>(&text).unwrap(), cmp);
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    let keys: Vec<&str> = v.as_object().unwrap().keys().map(String::as_str).collect();
    assert_eq!(
        keys,
        ["baseline", "baseline_index", "findings", "links", "runs"]
    );
    assert!(v["runs"][0]["to_baseline"]["electric_energy"].is_f64());
    assert!(v["links"][2]["runs"][0]["electric_energy_ratio"].is_null());

    let runs = paper_runs();
    let text = render_metrics(&runs, Format::Json).unwrap();
    assert_eq!(
        serde_json::from_str::<Vec<RunMetrics>>(&text).unwrap(),
        runs
    );
}

fn cells(line: &str) -> usize {
    line.split(',').count()
}

/// 19 run columns + 4 ratios + 11 peak/energy columns + 3 per joint (3 joints) + 3 per contact
/// (2 contacts) + `not_compared` = 50; metrics only: 19 + 11 + 2 * 3 + 3 * 2 = 42.
#[test]
fn csv_has_a_header_and_one_row_per_run_of_equal_width() {
    let text = render_comparison(&comparison(), Format::Csv).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 1 + 3);
    assert!(lines.iter().all(|l| cells(l) == 50), "{text}");
    let head: Vec<&str> = lines[0].split(',').collect();
    for col in ["run", "E_total_j", "E_total_ratio", "W.joint1_j", "E.joint1_j", "E.joint3_ratio", "pull.elbow7_s"] {
        assert!(head.contains(&col), "{col} not in {head:?}");
    }
    let row: Vec<&str> = lines[1].split(',').collect();
    let at = |col: &str| row[head.iter().position(|h| *h == col).unwrap()];
    assert_eq!((at("run"), at("E_total_j"), at("E_total_ratio")), ("two-elbow", "6", "0.6"));
    assert_eq!((at("W.joint2_j"), at("E.joint2_j"), at("E.joint1_ratio")), ("1", "3", "0.4"));
    assert_eq!((at("pull.elbow7_s"), at("first_pull.elbow7_s"), at("E.joint3_ratio")), ("0.31", "0.2", ""));
    let last: Vec<&str> = lines[3].split(',').collect(); // no-elbow has no contacts: empty cells
    assert_eq!(last[head.len() - 3..], ["", "", ""]);

    let text = render_metrics(&paper_runs(), Format::Csv).unwrap();
    assert!(
        text.lines().all(|l| cells(l) == 42) && text.lines().count() == 4,
        "{text}"
    );
    assert!(!text.contains("ratio"));
}

#[test]
fn csv_quotes_fields_with_commas_and_quotes() {
    let mut runs = paper_runs();
    runs[0].run = "a,\"b\"".into();
    let text = render_metrics(&runs, Format::Csv).unwrap();
    assert!(
        text.lines().nth(1).unwrap().starts_with("\"a,\"\"b\"\"\","),
        "{text}"
    );
}

/// Every line of a section (header, rule, rows) has the same width: columns are aligned.
#[test]
fn table_sections_are_aligned_with_units_and_findings() {
    let text = render_comparison(&comparison(), Format::Table).unwrap();
    for want in [
        "Runs (* = baseline",
        "no-elbow *",
        "z rms [mm]",
        "E / E_base",
        "Per-link energy",
        "W two-elbow [J]",
        "E/E_base two-elbow",
        "Contacts",
        "max |C'| [m/s]",
        "Energy balance",
        "Findings",
        "A real table cannot pull.",
    ] {
        assert!(text.contains(want), "{want:?} missing in\n{text}");
    }
    for section in text.split("\n\n").filter(|s| !s.starts_with("Findings")) {
        let widths: Vec<usize> = section.lines().skip(1).map(|l| l.chars().count()).collect();
        assert!(
            widths.len() >= 3 && widths.iter().all(|&w| w == widths[0]),
            "{section}"
        );
    }
    // one joint row per joint, values with their decimals: two-elbow W_1 = 1 J, E_1 = 2 J
    let link_row = text.lines().find(|l| l.starts_with("joint1 ")).unwrap();
    let v: Vec<&str> = link_row.split_whitespace().collect();
    assert_eq!(
        v,
        ["joint1", "1.0000", "1.0000", "1.0000", "2.0000", "3.0000", "5.0000", "0.400", "0.600"]
    );
}

#[test]
fn metrics_table_has_no_ratios_or_findings() {
    let text = render_metrics(&paper_runs(), Format::Table).unwrap();
    assert!(
        text.starts_with("Runs\n") && text.contains("Hand error"),
        "{text}"
    );
    assert!(
        !text.contains("base") && !text.contains("Findings"),
        "{text}"
    );
}

/// The synthetic unilateral run next to a bilateral one: the table gains a "Contact states"
/// section with one row per contact of the unilateral run; the CSV 14 columns per such contact
/// (empty cells for the bilateral run), the bilateral-only CSV is unchanged; JSON round-trips.
#[test]
fn contact_states_get_rows_columns_and_json() {
    let dir = tempfile::tempdir().unwrap();
    let (s, _) = schemas::synth::unilateral();
    let uni = crate::metrics::read_run_metrics(&s.write_in(dir.path())).unwrap();
    let runs = paper_runs();
    let plain = render_metrics(&runs, Format::Csv).unwrap();
    let all: Vec<RunMetrics> = runs.iter().cloned().chain([uni.clone()]).collect();

    let table = render_metrics(&all, Format::Table).unwrap();
    assert!(table.contains("Contact states"), "{table}");
    let section = &table[table.find("Contact states").unwrap()..];
    let rows: Vec<&str> = section.lines().take_while(|l| !l.is_empty()).filter(|l| l.starts_with("unilateral")).collect();
    assert_eq!(rows.len(), 2, "{section}");
    let row = rows[0];
    assert!(row.contains("elbow4"), "{row}");
    for cell in ["0.600", "0.5960", "0.300", "10.000"] {
        assert!(row.contains(cell), "{cell} in {row}");
    }
    assert!(!render_metrics(&runs, Format::Table).unwrap().contains("Contact states"));

    let csv = render_metrics(&all, Format::Csv).unwrap();
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(cells(lines[0]), cells(plain.lines().next().unwrap()) + 2 * 14);
    assert!(lines.iter().all(|l| cells(l) == cells(lines[0])));
    let head: Vec<&str> = lines[0].split(',').collect();
    let col = |name: &str| head.iter().position(|h| *h == name).unwrap_or_else(|| panic!("{name} in {head:?}"));
    let last: Vec<&str> = lines[4].split(',').collect();
    assert_eq!(last[col("in_contact.elbow4_s")].parse::<f64>().unwrap(), uni.contact_states[0].time_in_contact_s);
    assert_eq!(last[col("impacts.elbow4")], "1");
    assert_eq!(last[col("mu_stick.elbow7_ratio")], "0.25");
    assert_eq!(lines[1].split(',').nth(col("impacts.elbow4")), Some(""), "no such contact state in two-elbow");

    let json = render_metrics(&all, Format::Json).unwrap();
    assert_eq!(serde_json::from_str::<Vec<RunMetrics>>(&json).unwrap(), all);
}

/// The numbers in `text`: every piece between characters no number has that parses as one.
pub(crate) fn numbers(text: &str) -> std::collections::BTreeSet<String> {
    text.split(|c: char| !(c.is_ascii_digit() || matches!(c, '.' | '-' | '+' | 'e')))
        .filter(|t| t.chars().any(|c| c.is_ascii_digit()) && t.parse::<f64>().is_ok())
        .map(String::from)
        .collect()
}

/// The brief comparison: the findings first, then one row per run, at most 100 columns; every
/// number of its table is printed as the full tables print it (so found there); a unilateral
/// run's contacts say how long they stayed closed.
#[test]
fn every_number_of_the_brief_is_in_the_full_tables() {
    let dir = tempfile::tempdir().unwrap();
    let (s, _) = schemas::synth::unilateral();
    let uni = crate::metrics::read_run_metrics(&s.write_in(dir.path())).unwrap();
    let mut runs = paper_runs();
    runs[0].contact_forces[0].pull_time_s = 0.31;
    runs[0].contact_forces[0].min_normal_force_n = -4.0;
    runs.push(uni);
    let cmp = Comparison::new(&runs, None).unwrap();
    let brief = render_comparison_brief(&cmp, 100);
    assert!(brief.starts_with("Findings\n- "), "{brief}");
    assert!(brief.lines().all(|l| unicode_width::UnicodeWidthStr::width(l) <= 100), "{brief}");
    let table = &brief[brief.find("\nrun ").unwrap()..];
    assert!(table.contains("E_total_j") && table.contains("E_ratio") && table.contains("e_rms_mm") && table.contains("e_max_mm"), "{table}");
    assert!(table.contains("no-elbow *"), "{table}");
    assert!(table.contains("elbow4 pulls 0.310 s, min -4.000 N"), "{table}");
    assert!(table.contains(" closed "), "{table}");
    let full = render_comparison(&cmp, Format::Table).unwrap();
    let missing: Vec<String> = numbers(table).difference(&numbers(&full)).cloned().collect();
    assert!(missing.is_empty(), "{missing:?} of the brief not in the full tables:\n{table}\n{full}");
    // narrower: split into column groups, nothing lost
    let narrow = render_comparison_brief(&cmp, 60);
    assert!(narrow.lines().all(|l| unicode_width::UnicodeWidthStr::width(l) <= 60), "{narrow}");
    assert_eq!(numbers(&narrow[narrow.find("\nrun ").unwrap()..]), numbers(table));
}

/// The full tables fitted to a width keep every number (every cell), each line within it;
/// without a width they are as wide as they come.
#[test]
fn full_tables_fitted_to_a_width_keep_every_number() {
    let cmp = comparison();
    let wide = render_comparison(&cmp, Format::Table).unwrap();
    assert_eq!(render_comparison_fitted(&cmp, Format::Table, None).unwrap(), wide);
    for width in [60, 80, 120] {
        let text = render_comparison_fitted(&cmp, Format::Table, Some(width)).unwrap();
        assert!(text.lines().all(|l| unicode_width::UnicodeWidthStr::width(l) <= width), "{width}:\n{text}");
        assert_eq!(numbers(&text), numbers(&wide), "{width}:\n{text}");
    }
    assert_eq!(render_comparison_fitted(&cmp, Format::Json, Some(60)).unwrap(), render_comparison(&cmp, Format::Json).unwrap());
}

/// The supply's energies (issue 26) sit beside E in the energy totals (table and CSV) when a
/// run models its supply, read from its `energy_terms`; the paper's runs get no new column.
#[test]
fn the_supply_energy_sits_beside_e_only_when_a_run_has_a_supply() {
    let plain = paper_runs();
    for f in [Format::Table, Format::Csv] {
        let text = render_metrics(&plain, f).unwrap();
        assert!(!text.contains("supply"), "{f}: {text}");
    }
    let mut runs = paper_runs();
    runs[1].energy_terms = Some(schemas::EnergyTermsRecord {
        supply_energy: Some(7.25),
        supply_regenerated: Some(0.5),
        supply_dumped: Some(0.125),
        ..Default::default()
    });
    let csv = render_metrics(&runs, Format::Csv).unwrap();
    let lines: Vec<&str> = csv.lines().collect();
    let head: Vec<&str> = lines[0].split(',').collect();
    let col = |name: &str| head.iter().position(|h| *h == name).unwrap_or_else(|| panic!("{name} in {head:?}"));
    let (es, rg, du, e) = (col("E_supply_j"), col("supply_regenerated_j"), col("supply_dumped_j"), col("E_total_j"));
    assert_eq!(es, col("W_total_j") + 1);
    let row: Vec<&str> = lines[2].split(',').collect();
    assert_eq!((row[es], row[rg], row[du]), ("7.25", "0.5", "0.125"));
    assert_eq!(row[e].parse::<f64>().unwrap(), runs[1].electric_energy_total_j.unwrap());
    // the runs without a supply: empty cells, not a made-up number
    let other: Vec<&str> = lines[1].split(',').collect();
    assert_eq!((other[es], other[rg], other[du]), ("", "", ""));
    let table = render_metrics(&runs, Format::Table).unwrap();
    let totals = table.split("Energy totals at t_end").nth(1).unwrap();
    assert!(totals.contains("E_supply [J]") && totals.contains("regenerated [J]") && totals.contains("dumped [J]"), "{totals}");
    assert!(totals.contains("7.2500") && totals.contains("0.1250"), "{totals}");
}
