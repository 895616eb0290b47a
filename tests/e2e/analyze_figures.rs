//! `analyze figures` on synthetic recordings: every figure is written as a valid PNG of the
//! right size with real content and as an SVG with its labels, and the index pages list them all.

use std::collections::HashSet;
use std::path::{Path, PathBuf};
use std::process::Command;

use schemas::synth::{contact_forces, energy, Synth};
use schemas::{HandState, MotorState, Vec3};

const JOINTS: usize = 10;

/// A 1 s run at 1 kHz of a 10-joint arm: the hand circles (radius 0.05 m) and sags by `sag` m,
/// W_j and E_j grow with t, currents and voltages oscillate, each contact's force is
/// `-2 + 5 sin` N.
fn write_run(dir: &Path, run: &str, contacts: &[&str], sag: f64) -> PathBuf {
    let tau = 2.0 * std::f64::consts::PI;
    let per = |f: &dyn Fn(f64) -> f64| (0..JOINTS).map(|j| f((j + 1) as f64)).collect::<Vec<_>>();
    let mut s = Synth::new(run, contacts, JOINTS);
    (s.dt, s.n) = (1e-3, 1000);
    s.hand = Some(Box::new(move |t| {
        let desired = Vec3 { x: 0.3 + 0.05 * (tau * t).cos(), y: 0.05 * (tau * t).sin(), z: 0.0 };
        let actual = Vec3 { x: desired.x + 0.01 * sag * t, y: desired.y, z: -sag * (tau * t / 2.0).sin().abs() };
        let error = Vec3 { x: actual.x - desired.x, y: 0.0, z: actual.z };
        HandState { actual, desired, error, error_norm: (error.x * error.x + error.z * error.z).sqrt(), ..Default::default() }
    }));
    s.motors = Some(Box::new(move |t| MotorState {
        current: per(&|j| j * (tau * t + j).sin() * (1.0 + sag)),
        voltage: per(&|j| 2.0 * j * (tau * t).cos()),
        ..Default::default()
    }));
    let nc = contacts.len();
    s.constraints = Some(contact_forces(move |t| (0..nc).map(|c| [(-2.0 + 5.0 * (tau * t).sin()) * (c + 1) as f64, 0.0, 0.0]).collect()));
    s.energy = Some(Box::new(move |t| energy(per(&|j| j * t * t), per(&|j| (1.0 + 10.0 * sag) * j * t))));
    s.result = None;
    s.write(&dir.join(format!("paper-{run}.mcap")))
}

fn paper_runs(dir: &Path) {
    write_run(dir, "two-elbow", &["elbow4", "elbow7"], 0.01);
    write_run(dir, "one-elbow", &["elbow4"], 0.05);
    write_run(dir, "no-elbow", &[], 0.2);
}

/// The stems the paper's three runs of a 10-joint arm give, in index order.
fn expected_stems() -> Vec<String> {
    let mut v: Vec<String> = [
        "fig01_xy",
        "fig02_xz",
        "fig03_yz",
        "fig04_work_total",
        "fig05_electric_total",
    ]
    .map(String::from)
    .to_vec();
    for l in 1..=10 {
        v.push(format!("fig{:02}_work_link{l:02}", 4 + 2 * l));
        v.push(format!("fig{:02}_electric_link{l:02}", 5 + 2 * l));
    }
    v.extend(
        [
            "extra_currents",
            "extra_voltages",
            "extra_normal_forces",
            "extra_hand_error",
        ]
        .map(String::from),
    );
    v
}

/// The text content of every `<text>` element of an SVG, tspans included, trimmed.
fn texts(svg: &str) -> Vec<String> {
    let mut out = Vec::new();
    for part in svg.split("<text").skip(1) {
        let body = &part[part.find('>').map_or(0, |k| k + 1)..part.find("</text>").unwrap_or(part.len())];
        let mut t = String::new();
        let mut in_tag = false;
        for c in body.chars() {
            match c {
                '<' => in_tag = true,
                '>' => in_tag = false,
                c if !in_tag => t.push(c),
                _ => {}
            }
        }
        out.push(t.trim().to_string());
    }
    out
}

/// A PNG that decodes, is at least 1000 x 700 and has many colours and non-white pixels.
fn assert_png_has_content(path: &Path) {
    let bytes = std::fs::read(path).unwrap();
    assert!(
        bytes.starts_with(b"\x89PNG\r\n\x1a\n"),
        "{}: not a PNG",
        path.display()
    );
    let img = image::load_from_memory_with_format(&bytes, image::ImageFormat::Png)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .to_rgb8();
    assert!(
        img.width() == 1000 && img.height() >= 700,
        "{}: {:?}",
        path.display(),
        img.dimensions()
    );
    let non_white = img.pixels().filter(|p| p.0 != [255, 255, 255]).count();
    let colours: HashSet<[u8; 3]> = img.pixels().map(|p| p.0).collect();
    assert!(
        non_white > 5000,
        "{}: only {non_white} non-white pixels",
        path.display()
    );
    assert!(
        colours.len() > 20,
        "{}: only {} colours",
        path.display(),
        colours.len()
    );
}

#[test]
fn every_figure_is_written_as_png_and_svg_and_indexed() {
    let dir = tempfile::tempdir().unwrap();
    let rec = dir.path().join("rec");
    std::fs::create_dir(&rec).unwrap();
    paper_runs(&rec);
    let out = dir.path().join("figs");
    let run = Command::new(env!("CARGO_BIN_EXE_analyze"))
        .args([
            "figures",
            rec.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );

    let md = std::fs::read_to_string(out.join("index.md")).unwrap();
    let html = std::fs::read_to_string(out.join("index.html")).unwrap();
    let mut last = 0;
    for stem in expected_stems() {
        assert_png_has_content(&out.join(format!("{stem}.png")));
        let svg = std::fs::read_to_string(out.join(format!("{stem}.svg"))).unwrap();
        let x_desc = if ["fig01", "fig02", "fig03"]
            .iter()
            .any(|p| stem.starts_with(p))
        {
            "[m]"
        } else {
            "time t [s]"
        };
        assert!(
            svg.starts_with("<svg") && svg.contains(x_desc),
            "{stem}.svg lacks {x_desc}"
        );
        for run in ["two-elbow", "one-elbow", "no-elbow"] {
            if stem != "extra_normal_forces" || run != "no-elbow" {
                assert!(
                    svg.contains(run),
                    "{stem}.svg has no legend entry for {run}"
                );
            }
        }
        let img = format!("]({stem}.png)");
        let at = md
            .find(&img)
            .unwrap_or_else(|| panic!("index.md lacks {img}"));
        assert!(at > last, "{stem} out of order in index.md");
        last = at;
        assert!(
            html.contains(&format!("<img src=\"{stem}.png\"")),
            "index.html lacks {stem}"
        );
    }
    let sub = |x: &str| format!(r#"<tspan baseline-shift="sub" font-size="70%">{x}</tspan>"#);
    let xy = std::fs::read_to_string(out.join("fig01_xy.svg")).unwrap();
    assert!(xy.contains("x [m]") && xy.contains("y [m]") && xy.contains(&format!("target r{}", sub("d"))), "{xy}");
    let fig4 = std::fs::read_to_string(out.join("fig04_work_total.svg")).unwrap();
    assert!(fig4.contains("Fig. 4: All link work") && fig4.contains("W [J]"));
    let fig25 = std::fs::read_to_string(out.join("fig25_electric_link10.svg")).unwrap();
    assert!(fig25.contains("Electric energy of the tenth link") && fig25.contains(&format!("E{} [J]", sub("10"))));
    let forces = std::fs::read_to_string(out.join("extra_normal_forces.svg")).unwrap();
    assert!(forces.contains("elbow7") && forces.contains(&format!("f{} [N]", sub("n"))), "{forces}");
    assert!(
        md.contains("Fig. 25: Electric energy of the tenth link, E<sub>10</sub>")
            && md.contains("Beyond the paper")
    );
    // no figure text shows a literal underscore or caret (sub/superscripts are tspans)
    for stem in expected_stems() {
        let svg = std::fs::read_to_string(out.join(format!("{stem}.svg"))).unwrap();
        for text in texts(&svg) {
            assert!(!text.contains('_') && !text.contains('^'), "{stem}.svg: {text:?}");
        }
    }
    // small multiples: one panel per joint (10), one per contact (2: elbow4, elbow7)
    let panels = |stem: &str, prefix: &str| texts(&std::fs::read_to_string(out.join(format!("{stem}.svg"))).unwrap()).iter().filter(|t| t.starts_with(prefix)).count();
    assert_eq!(panels("extra_currents", "joint "), JOINTS);
    assert_eq!(panels("extra_voltages", "joint "), JOINTS);
    assert_eq!(panels("extra_normal_forces", "elbow"), 2);
    let files = std::fs::read_dir(&out).unwrap().count();
    assert_eq!(files, 2 * expected_stems().len() + 2);
}

/// The library call: figures follow the joints in the data; a recording without `/constraints`
/// and `/motors` still gives every figure (saying there is no data).
#[test]
fn the_library_draws_what_the_recordings_have() {
    let dir = tempfile::tempdir().unwrap();
    let path = write_run(dir.path(), "solo", &[], 0.1);
    let mut run = analyze::figures::read_run(&path).unwrap();
    assert_eq!(
        (
            run.name.as_str(),
            run.work.cols.len(),
            run.actual.cols.len()
        ),
        ("solo", 10, 3)
    );
    run.current = Default::default();
    run.voltage = Default::default();
    run.work.cols.truncate(2);
    run.electric.cols.truncate(2);
    let out = dir.path().join("f");
    let figs = analyze::figures::write_all(&[run], &[path], &out).unwrap();
    let stems: Vec<&str> = figs.iter().map(|f| f.stem.as_str()).collect();
    assert_eq!(stems.len(), 5 + 4 + 4, "{stems:?}");
    assert_eq!(
        &stems[5..9],
        [
            "fig06_work_link01",
            "fig07_electric_link01",
            "fig08_work_link02",
            "fig09_electric_link02"
        ]
    );
    assert_eq!(figs[8].number, Some(9));
    assert!(figs[9].number.is_none());
    let svg = std::fs::read_to_string(out.join("extra_currents.svg")).unwrap();
    assert!(svg.contains("no data"), "{svg}");
    assert_png_has_content(&out.join("fig01_xy.png"));
}
