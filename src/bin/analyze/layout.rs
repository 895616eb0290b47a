//! `analyze layout`: the Foxglove layout of recordings (`schemas::layout`, the one owner of the
//! format; `sim` writes the same beside its recordings). Each recording is read streamed and
//! only the box around its desired hand positions is kept: memory does not grow with the
//! recording.

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

/// The lowest and highest finite desired hand position, per axis, of the `/hand` messages seen.
struct TargetBox(Option<([f64; 3], [f64; 3])>);

impl schemas::Visitor for TargetBox {
    fn message(&mut self, m: schemas::DecodedMessage<'_>) -> Result<(), schemas::Error> {
        // a message without a target (another producer's /hand) places no camera, as in
        // `LayoutInput::from_recording`
        let Ok(h) = m.decode::<schemas::HandState>(None) else { return Ok(()) };
        let q = [h.desired.x, h.desired.y, h.desired.z];
        if q.iter().all(|v| v.is_finite()) {
            let (lo, hi) = self.0.get_or_insert((q, q));
            for k in 0..3 {
                lo[k] = lo[k].min(q[k]);
                hi[k] = hi[k].max(q[k]);
            }
        }
        Ok(())
    }
}

/// The layout input of the recording at `p`, read streamed: the camera from the box around the
/// desired hand positions of `/hand` (the same as [`LayoutInput::from_recording`] gives from all
/// of them, which [`layout::camera_for`] reduces to that box).
/// With it, the line that says the run failed (if it did).
fn read_one(p: &std::path::Path) -> Result<(LayoutInput, Option<String>)> {
    let mut visit = TargetBox(None);
    let rec = schemas::stream_recording(p, Some(&[schemas::topics::HAND]), &mut visit)?;
    let mut one = LayoutInput::from_recording(&rec)?;
    let corners: Vec<[f64; 3]> = visit.0.map(|(lo, hi)| vec![lo, hi]).unwrap_or_default();
    (one.focus, one.camera_distance_m) = layout::camera_for(&corners);
    Ok((one, cli::inputs::failed_run_note(p, rec.result()?.as_ref())))
}

pub fn run(a: &LayoutArgs, v: Verbosity) -> Result<u8> {
    let expanded = cli::inputs::expand_all(&a.inputs)?;
    expanded.warn_skipped();
    // each recording on its own: one that cannot be read is reported and left out (exit 1)
    let (read, failed) = cli::inputs::each_file(&expanded.files, |p| read_one(p).with_context(|| format!("reading {}", p.display())))?;
    // one layout input per scene, in the order the scenes first appear
    let mut scenes: Vec<LayoutInput> = Vec::new();
    let mut failed = failed;
    for (p, (one, note)) in read {
        if let Some(note) = note {
            eprintln!("analyze: {note} (in the layout with the others)");
            failed += 1;
        }
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
                    eprintln!("analyze: wrote {} ({} run{}); in Foxglove: Layouts -> Import from file", path.display(), input.runs.len(), if input.runs.len() == 1 { "" } else { "s" });
                }
            }
        }
    }
    Ok(if failed > 0 || !expanded.skipped.is_empty() { exit::FAILED } else { exit::SUCCESS })
}
