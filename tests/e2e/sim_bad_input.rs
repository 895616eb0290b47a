//! Bad scenes through the `sim` binary (`sim check` and a run): exit status 2, the file, field
//! and value on stderr, no panic, nothing written. The library's table of bad scenes is
//! `sim/tests/bad_input.rs`.

use crate::run_sim;
use serde_json::json;
use sim::scene::{PAPER_SCENE_JSON, PAPER_URDF};

fn paper_json() -> serde_json::Value {
    serde_json::from_str(PAPER_SCENE_JSON).unwrap()
}

/// Through the binary: exit status 2, the file, field and value on stderr, no panic, no output.
#[test]
fn cli_rejects_bad_scenes_with_status_2() {
    let dir = tempfile::tempdir().unwrap();
    let write = |name: &str, json: &str, urdf: &str| {
        let d = dir.path().join(name);
        std::fs::create_dir(&d).unwrap();
        std::fs::write(d.join("paper_arm.urdf"), urdf).unwrap();
        let p = d.join("scene.json");
        std::fs::write(&p, json).unwrap();
        p
    };
    let mut v = paper_json();
    v["motor"]["resistance"] = json!(-1.1);
    let negative_r = write("negative-r", &v.to_string(), PAPER_URDF);
    let truncated = write("truncated", &PAPER_SCENE_JSON[..300], PAPER_URDF);
    let infinite = write("infinite", &PAPER_SCENE_JSON.replace("\"duration\": 5.0", "\"duration\": 1e999"), PAPER_URDF);
    let prismatic = write(
        "planar",
        PAPER_SCENE_JSON,
        &PAPER_URDF.replace(r#"<joint name="joint5" type="revolute">"#, r#"<joint name="joint5" type="planar">"#),
    );
    let not_xml = write("not-xml", PAPER_SCENE_JSON, "<<<");
    let missing = dir.path().join("missing.json");
    let out_dir = dir.path().join("out");
    let cases: [(&std::path::Path, &[&str]); 6] = [
        (&negative_r, &["field `motor.resistance` = -1.1", "must be > 0 ohm"]),
        (&truncated, &["field `(document)`", "EOF while parsing"]),
        (&infinite, &["field `duration` = 1e999", "number out of range"]),
        (&prismatic, &["paper_arm.urdf:53: <joint name=\"joint5\">: type=\"planar\""]),
        (&not_xml, &["the URDF could not be parsed"]),
        (&missing, &["(file)"]),
    ];
    for (k, (path, want)) in cases.iter().enumerate() {
        // `sim check FILE` and, for some, a run (`sim run FILE -o DIR`): nothing may be written
        let mut commands: Vec<Vec<&std::ffi::OsStr>> = vec![vec!["check".as_ref(), path.as_os_str()]];
        if k % 2 == 0 {
            commands.push(vec!["run".as_ref(), path.as_os_str(), "-o".as_ref(), out_dir.as_os_str(), "--quiet".as_ref()]);
        }
        for args in commands {
            let out = run_sim(&args);
            let stderr = String::from_utf8_lossy(&out.stderr);
            assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
            assert!(stderr.starts_with(&format!("sim: error: {}", path.display())), "{args:?}: {stderr}");
            for w in *want {
                assert!(stderr.contains(w), "{args:?}: {w:?} not in {stderr}");
            }
            assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
            assert!(out.stdout.is_empty(), "{args:?}: {}", String::from_utf8_lossy(&out.stdout));
        }
    }
    assert!(!out_dir.exists() || std::fs::read_dir(&out_dir).unwrap().next().is_none());
}
