//! `sim list`: the scenes built into the binary (`sim::scene::builtin`), each runnable by name.

use std::fmt::Write as _;

use anyhow::Result;
use cli::{exit, print_out, TableFormat};
use serde::Serialize;
use sim::scene::builtin::{Summary, BUILTINS};

/// List the scenes built into `sim`: name, degrees of freedom, runs and description. Run one
/// by name (`sim NAME`, `sim run NAME`), or write it out to edit (`sim export-scene NAME`).
#[derive(Debug, Clone, clap::Args)]
#[command(after_help = "\
Output: one row per built-in scene on stdout (name, DoF, robot, runs, description); -f json|csv
for machines.

Examples:
  sim list                              the built-in scenes
  sim list -f json                      the same for machines
  sim ur5e-like --duration 1            run one by name
  sim export-scene panda-like -o my-arm/")]
pub struct ListArgs {
    #[command(flatten)]
    pub format: TableFormat,
}

/// One row of the listing.
#[derive(Debug, Serialize)]
struct Row {
    name: String,
    dof: usize,
    robot: String,
    urdf: String,
    runs: Vec<String>,
    description: String,
}

impl From<Summary> for Row {
    fn from(s: Summary) -> Self {
        Row { name: s.name, dof: s.dof, robot: s.robot, urdf: s.urdf, runs: s.runs, description: s.description }
    }
}

pub fn run(a: &ListArgs) -> Result<u8> {
    let rows: Vec<Row> = BUILTINS.iter().map(|b| b.summary().map(Row::from)).collect::<Result<_, _>>()?;
    print_out(&render(&rows, a.format.format)?)?;
    Ok(exit::SUCCESS)
}

fn render(rows: &[Row], format: analyze::Format) -> Result<String> {
    Ok(match format {
        analyze::Format::Json => serde_json::to_string_pretty(rows)? + "\n",
        analyze::Format::Csv => {
            let mut w = csv::Writer::from_writer(Vec::new());
            w.write_record(["name", "dof", "robot", "urdf", "runs", "description"])?;
            for r in rows {
                w.write_record([r.name.as_str(), &r.dof.to_string(), &r.robot, &r.urdf, &r.runs.join(" "), &r.description])?;
            }
            String::from_utf8(w.into_inner()?)?
        }
        analyze::Format::Table => {
            let runs: Vec<String> = rows.iter().map(|r| r.runs.join(", ")).collect();
            let wn = rows.iter().map(|r| r.name.len()).max().unwrap_or(0).max("scene".len());
            let wr = runs.iter().map(String::len).max().unwrap_or(0).max("runs".len());
            let mut o = String::new();
            writeln!(o, "{:wn$}  {:>3}  {:wr$}  description", "scene", "DoF", "runs")?;
            for (r, runs) in rows.iter().zip(&runs) {
                writeln!(o, "{:wn$}  {:>3}  {:wr$}  {}", r.name, r.dof, runs, first_sentence(&r.description))?;
            }
            writeln!(o, "\nRun one with `sim NAME` (or `sim run NAME`); `sim list -f json` has the full descriptions.")?;
            o
        }
    })
}

/// The description up to its first sentence's end: a ". " before a capital letter, not after
/// an abbreviation like "et al." (the rest is in `-f json`).
fn first_sentence(d: &str) -> &str {
    let ends = d.match_indices(". ").map(|(i, _)| i).filter(|&i| {
        let next_is_capital = d[i + 2..].chars().next().is_some_and(char::is_uppercase);
        next_is_capital && !d[..i].ends_with(" al") && !d[..i].ends_with(" e.g")
    });
    ends.into_iter().next().map_or(d, |i| &d[..=i])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_table_has_one_row_per_builtin_and_the_json_every_field() {
        let rows: Vec<Row> = BUILTINS.iter().map(|b| b.summary().unwrap().into()).collect();
        let table = render(&rows, analyze::Format::Table).unwrap();
        assert_eq!(table.lines().filter(|l| BUILTINS.iter().any(|b| l.starts_with(&format!("{} ", b.name)))).count(), BUILTINS.len());
        let json: serde_json::Value = serde_json::from_str(&render(&rows, analyze::Format::Json).unwrap()).unwrap();
        assert_eq!(json.as_array().unwrap().len(), BUILTINS.len());
        assert_eq!(json[0]["name"], "paper");
        assert_eq!(json[0]["dof"], 10);
        assert_eq!(first_sentence("Gaz et al. 2019 say so. More here."), "Gaz et al. 2019 say so.");
        let csv = render(&rows, analyze::Format::Csv).unwrap();
        assert_eq!(csv.lines().next().unwrap(), "name,dof,robot,urdf,runs,description");
    }
}
