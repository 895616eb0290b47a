//! `analyze layout`: the Foxglove layout of recordings (`schemas::layout`, the one owner of the
//! format; `sim` writes the same beside its recordings).

use std::path::PathBuf;

use anyhow::{bail, Context, Result};
use cli::{exit, Verbosity};
use schemas::layout::{self, LayoutInput};

/// The Foxglove layout for recordings: a 3D panel (the arm from /robot_description, /tf, the
/// table and target path of /scene, the contact markers and force arrows of /contact_markers,
/// the hand points with a trail, a side view) and plots of the motor currents and voltages per
/// joint, the contact forces (and modes), the energies, the balance residual and the hand
/// error, labelled with joint and contact names and units. Recordings of one scene give one
/// layout (contacts that runs name differently are labelled per run).
#[derive(Debug, clap::Args)]
#[command(after_help = "\
Output: the layout JSON on stdout, or DIR/<scene>.foxglove-layout.json with -o. In Foxglove:
Layouts -> Import from file, choose it, then open a recording of the scene.

Examples:
  analyze layout out/paper-two-elbow.mcap > two-elbow.json
  analyze layout out/paper-two-elbow.mcap out/paper-no-elbow.mcap -o layouts
  analyze layout out/ -o out")]
pub struct LayoutArgs {
    /// Recordings (.mcap) of one scene, or directories: every *.mcap directly in them.
    #[arg(required = true, value_name = "FILES_OR_DIRS")]
    pub inputs: Vec<PathBuf>,
    /// Directory for <scene>.foxglove-layout.json (created if needed) [default: print to stdout].
    #[arg(short = 'o', long = "out", value_name = "DIR")]
    pub out: Option<PathBuf>,
}

pub fn run(a: &LayoutArgs, v: Verbosity) -> Result<u8> {
    let paths = cli::inputs::expand(&a.inputs)?;
    let mut merged: Option<LayoutInput> = None;
    for p in &paths {
        let rec = schemas::read_recording_topics(p, Some(&[schemas::topics::HAND])).with_context(|| format!("reading {}", p.display()))?;
        let one = LayoutInput::from_recording(&rec).with_context(|| format!("reading {}", p.display()))?;
        merged = Some(match merged {
            None => one,
            Some(mut m) => {
                if m.title != one.title || m.joint_names != one.joint_names {
                    bail!(
                        "{}: scene `{}` with joints [{}], but the recordings before it are of scene `{}` with joints [{}]: one layout is for one scene (run `analyze layout` per scene)",
                        p.display(),
                        one.title,
                        one.joint_names.join(", "),
                        m.title,
                        m.joint_names.join(", ")
                    );
                }
                m.runs.extend(one.runs);
                for k in 0..3 {
                    m.focus[k] = (m.focus[k] + one.focus[k]) / 2.0;
                }
                m.camera_distance_m = m.camera_distance_m.max(one.camera_distance_m);
                m
            }
        });
    }
    let Some(input) = merged else { bail!("no recordings in {:?}", a.inputs) };
    let text = serde_json::to_string_pretty(&layout::foxglove(&input)).context("the layout as JSON")? + "\n";
    match &a.out {
        None => cli::print_out(&text)?,
        Some(dir) => {
            cli::create_dir(dir)?;
            let path = dir.join(layout::file_name(&input.title));
            schemas::atomic::write_file(&path, &text).with_context(|| format!("cannot write {}", path.display()))?;
            if !v.quiet {
                eprintln!("analyze: wrote {} ({} runs); in Foxglove: Layouts -> Import from file", path.display(), input.runs.len());
            }
        }
    }
    Ok(exit::SUCCESS)
}
