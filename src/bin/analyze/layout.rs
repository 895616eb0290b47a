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
Output: the layout JSON on stdout, or DIR/<scene>.foxglove-layout.json per scene with -o. In Foxglove:
Layouts -> Import from file, choose it, then open a recording of the scene.

Examples:
  analyze layout out/paper-two-elbow.mcap > two-elbow.json
  analyze layout out/paper-two-elbow.mcap out/paper-no-elbow.mcap -o layouts
  analyze layout out/ -o out")]
pub struct LayoutArgs {
    /// Recordings (.mcap), or directories: every *.mcap directly in them. Recordings of one
    /// scene give one layout.
    #[arg(required = true, value_name = "FILES_OR_DIRS")]
    pub inputs: Vec<PathBuf>,
    /// Directory for <scene>.foxglove-layout.json, one per scene (created if needed) [default:
    /// print the one scene's layout to stdout].
    #[arg(short = 'o', long = "out", value_name = "DIR")]
    pub out: Option<PathBuf>,
}

pub fn run(a: &LayoutArgs, v: Verbosity) -> Result<u8> {
    let paths = cli::inputs::expand(&a.inputs)?;
    // one layout input per scene, in the order the scenes first appear
    let mut scenes: Vec<LayoutInput> = Vec::new();
    for p in &paths {
        let rec = schemas::read_recording_topics(p, Some(&[schemas::topics::HAND])).with_context(|| format!("reading {}", p.display()))?;
        let one = LayoutInput::from_recording(&rec).with_context(|| format!("reading {}", p.display()))?;
        match scenes.iter_mut().find(|m| m.title == one.title) {
            None => scenes.push(one),
            Some(m) => {
                if m.joint_names != one.joint_names {
                    bail!(
                        "{}: scene `{}` with joints [{}], but other recordings of that scene have joints [{}]: one layout needs one set of joints",
                        p.display(),
                        one.title,
                        one.joint_names.join(", "),
                        m.joint_names.join(", ")
                    );
                }
                m.runs.extend(one.runs);
                for k in 0..3 {
                    m.focus[k] = (m.focus[k] + one.focus[k]) / 2.0;
                }
                m.camera_distance_m = m.camera_distance_m.max(one.camera_distance_m);
            }
        }
    }
    let json = |input: &LayoutInput| -> Result<String> { Ok(serde_json::to_string_pretty(&layout::foxglove(input)).context("the layout as JSON")? + "\n") };
    match &a.out {
        None => match scenes.as_slice() {
            [one] => cli::print_out(&json(one)?)?,
            [] => bail!("no recordings in {:?}", a.inputs),
            many => bail!(
                "the recordings are of {} scenes ({}): give -o DIR for one layout per scene",
                many.len(),
                many.iter().map(|m| m.title.as_str()).collect::<Vec<_>>().join(", ")
            ),
        },
        Some(dir) => {
            cli::create_dir(dir)?;
            for input in &scenes {
                let path = dir.join(layout::file_name(&input.title));
                schemas::atomic::write_file(&path, json(input)?).with_context(|| format!("cannot write {}", path.display()))?;
                if !v.quiet {
                    eprintln!("analyze: wrote {} ({} runs); in Foxglove: Layouts -> Import from file", path.display(), input.runs.len());
                }
            }
        }
    }
    Ok(exit::SUCCESS)
}
