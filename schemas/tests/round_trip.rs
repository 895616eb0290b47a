//! Write every message type with `RecordingWriter`, read back with the GENERIC reader (which
//! knows nothing of our structs) and compare field by field. Tolerance: none. Protobuf `double`
//! and CDR `float64` are the IEEE bits, so f64s are compared bit for bit (`to_bits`), which
//! also distinguishes -0.0 and keeps NaN payloads.


use crate::common::{bits, content, f, fv, tf, val, write_all, URDF};
use schemas::{
    from_log_time, read_recording, topics, HAND_ACTUAL_RGBA, HAND_DESIRED_RGBA, ArraySizes, ConstraintState, EnergyState, HandState, JointState,
    MotorState, RecordingWriter, Value,
};

#[test]
fn every_message_type_round_trips_through_the_generic_reader() {
    let dir = tempfile::tempdir().unwrap();
    let c = content(6);
    let path = write_all(&dir.path().join("run.mcap"), &c);
    let r = read_recording(&path).unwrap();

    // metadata: caller's entries plus the format version
    assert_eq!(r.metadata_records().get("recording").and_then(|m| m.get("scene")).map(String::as_str), Some("two_link"));
    assert_eq!(r.metadata_records().get("recording").and_then(|m| m.get("integrator")).map(String::as_str), Some("rk4"));
    assert_eq!(r.metadata_records().get("solver").and_then(|m| m.get("dt")).map(String::as_str), Some("0.001"));
    assert_eq!(r.format_version(), Some(schemas::FORMAT_VERSION));

    // channels in order of first use, with the encodings VIEWERS.md asks for
    let chans: Vec<(&str, &str, &str, &str, usize)> = r
        .channels
        .iter()
        .map(|c| {
            (
                c.topic.as_str(),
                c.schema_name.as_str(),
                c.schema_encoding.as_str(),
                c.message_encoding.as_str(),
                c.message_count,
            )
        })
        .collect();
    assert_eq!(
        chans,
        vec![
            (
                "/robot_description",
                "std_msgs/msg/String",
                "ros2msg",
                "cdr",
                1
            ),
            ("/tf", "foxglove.FrameTransforms", "protobuf", "protobuf", 6),
            (
                "/joint_states",
                "sensor_msgs/msg/JointState",
                "ros2msg",
                "cdr",
                6
            ),
            (
                "/motors",
                "motorstate.MotorState",
                "protobuf",
                "protobuf",
                6
            ),
            (
                "/constraints",
                "constraintstate.ConstraintState",
                "protobuf",
                "protobuf",
                6
            ),
            ("/hand", "handstate.HandState", "protobuf", "protobuf", 6),
            (
                "/energy",
                "energystate.EnergyState",
                "protobuf",
                "protobuf",
                6
            ),
            (
                "/hand_points",
                "foxglove.PointCloud",
                "protobuf",
                "protobuf",
                6
            ),
        ]
    );
    assert!(r.channels.iter().all(|c| c.undecoded.is_none()));

    let urdf = &r.messages("/robot_description").unwrap();
    assert_eq!(urdf.len(), 1);
    assert_eq!(
        (urdf[0].0, urdf[0].1.get("data").and_then(Value::as_str)),
        (0, Some(URDF))
    );

    for (k, &t) in c.times.iter().enumerate() {
        let m = &r.messages("/motors").unwrap()[k];
        assert_eq!(m.0, t);
        let want = &c.motors[k];
        assert_eq!(f(&m.1, "time"), want.time.to_bits());
        assert_eq!(fv(&m.1, "current"), bits(&want.current));
        assert_eq!(fv(&m.1, "voltage"), bits(&want.voltage));
        assert_eq!(fv(&m.1, "back_emf"), bits(&want.back_emf));
        assert_eq!(fv(&m.1, "electric_power"), bits(&want.electric_power));
        assert_eq!(fv(&m.1, "torque"), bits(&want.torque));

        let m = &r.messages("/constraints").unwrap()[k].1;
        let want = &c.constraints[k];
        assert_eq!(f(m, "time"), want.time.to_bits());
        assert_eq!(fv(m, "normal_force"), bits(&want.normal_force));
        assert_eq!(fv(m, "position"), bits(&want.position));
        assert_eq!(fv(m, "velocity"), bits(&want.velocity));

        let m = &r.messages("/hand").unwrap()[k].1;
        let want = &c.hands[k];
        for (name, v) in [
            ("actual", want.actual),
            ("desired", want.desired),
            ("error", want.error),
        ] {
            assert_eq!(f(m, &format!("{name}.x")), v.x.to_bits());
            assert_eq!(f(m, &format!("{name}.y")), v.y.to_bits());
            assert_eq!(f(m, &format!("{name}.z")), v.z.to_bits());
        }
        assert_eq!(f(m, "error_norm"), want.error_norm.to_bits());

        let m = &r.messages("/energy").unwrap()[k].1;
        let want = &c.energies[k];
        assert_eq!(fv(m, "link_work"), bits(&want.link_work));
        assert_eq!(fv(m, "electric_energy"), bits(&want.electric_energy));
        for (name, x) in [
            ("time", want.time),
            ("link_work_total", want.link_work_total),
            ("electric_energy_total", want.electric_energy_total),
            ("kinetic", want.kinetic),
            ("potential", want.potential),
            ("magnetic", want.magnetic),
            ("resistive_loss", want.resistive_loss),
            ("friction_loss", want.friction_loss),
            ("balance_residual", want.balance_residual),
        ] {
            assert_eq!(f(m, name), x.to_bits(), "energy.{name}");
        }

        let m = &r.messages("/joint_states").unwrap()[k].1;
        let want = &c.joints[k];
        let sec = m.get("header.stamp.sec").and_then(Value::as_f64).unwrap() as u64;
        let nsec = m
            .get("header.stamp.nanosec")
            .and_then(Value::as_f64)
            .unwrap() as u64;
        assert_eq!(sec * 1_000_000_000 + nsec, want.stamp_ns);
        assert_eq!(
            m.get("header.frame_id").and_then(Value::as_str),
            Some(want.frame_id.as_str())
        );
        let names: Vec<&str> = m
            .get("name")
            .and_then(Value::as_list)
            .unwrap()
            .iter()
            .filter_map(Value::as_str)
            .collect();
        assert_eq!(names, want.name);
        assert_eq!(fv(m, "position"), bits(&want.position));
        assert_eq!(fv(m, "velocity"), bits(&want.velocity));
        assert_eq!(fv(m, "effort"), bits(&want.effort));

        let m = &r.messages("/tf").unwrap()[k].1;
        let want = tf(t, k);
        let list = m.get("transforms").and_then(Value::as_list).unwrap();
        assert_eq!(list.len(), want.transforms.len());
        for (i, w) in want.transforms.iter().enumerate() {
            let p = |s: &str| format!("transforms.{i}.{s}");
            assert_eq!(
                m.get(&p("parent_frame_id")).and_then(Value::as_str),
                Some(w.parent_frame_id.as_str())
            );
            assert_eq!(
                m.get(&p("child_frame_id")).and_then(Value::as_str),
                Some(w.child_frame_id.as_str())
            );
            // Foxglove's well-known types are prost-generated proto3: prost omits a field equal
            // to 0, so -0.0 comes back as +0.0 there (our derived messages keep it, see above)
            let pz = |x: f64| {
                if x == 0.0 {
                    0.0f64.to_bits()
                } else {
                    x.to_bits()
                }
            };
            let (tr, rot) = (w.translation.unwrap(), w.rotation.unwrap());
            assert_eq!(
                [
                    f(m, &p("translation.x")),
                    f(m, &p("translation.y")),
                    f(m, &p("translation.z"))
                ],
                [pz(tr.x), pz(tr.y), pz(tr.z)]
            );
            assert_eq!(
                [
                    f(m, &p("rotation.x")),
                    f(m, &p("rotation.y")),
                    f(m, &p("rotation.z")),
                    f(m, &p("rotation.w"))
                ],
                [pz(rot.x), pz(rot.y), pz(rot.z), pz(rot.w)]
            );
            // google.protobuf.Timestamp on the wire
            let secs = m
                .get(&p("timestamp.seconds"))
                .and_then(Value::as_f64)
                .unwrap() as u64;
            let nanos = m
                .get(&p("timestamp.nanos"))
                .and_then(Value::as_f64)
                .unwrap() as u64;
            assert_eq!(secs * 1_000_000_000 + nanos, t);
        }

        let m = &r.messages("/hand_points").unwrap()[k].1;
        assert_eq!(m.get("frame_id").and_then(Value::as_str), Some("world"));
        assert_eq!(m.get("point_stride").and_then(Value::as_f64), Some(28.0));
        let names: Vec<&str> = (0..7)
            .map(|i| {
                m.get(&format!("fields.{i}.name"))
                    .and_then(Value::as_str)
                    .unwrap()
            })
            .collect();
        assert_eq!(names, ["x", "y", "z", "red", "green", "blue", "alpha"]);
        let Some(Value::Bytes(data)) = m.get("data") else {
            panic!("no point data")
        };
        // per point: x, y, z as f64, then the colour as 4 bytes
        let pts: Vec<u64> = data
            .chunks_exact(28)
            .flat_map(|p| p[..24].chunks_exact(8).map(|b| u64::from_le_bytes(b.try_into().unwrap())))
            .collect();
        assert_eq!(pts, bits(&[1.0, 2.0, 3.0, val(k, 0), -0.0, 9.5]));
        let colours: Vec<&[u8]> = data.chunks_exact(28).map(|p| &p[24..]).collect();
        assert_eq!(colours, [&HAND_ACTUAL_RGBA[..], &HAND_DESIRED_RGBA[..]]);
    }

    // typed reading: times from the log times, every field bit for bit
    let motors = r.read::<MotorState>().unwrap();
    assert_eq!(motors.iter().map(|m| m.0).collect::<Vec<_>>(), c.times.iter().map(|&n| from_log_time(n)).collect::<Vec<_>>());
    assert_eq!(motors.iter().map(|m| bits(&m.1.current)).collect::<Vec<_>>(), c.motors.iter().map(|m| bits(&m.current)).collect::<Vec<_>>());
    // (Debug text: NaN equals itself there, and -0.0 differs from 0.0)
    let same = |a: &dyn std::fmt::Debug, b: &dyn std::fmt::Debug| assert_eq!(format!("{a:?}"), format!("{b:?}"));
    same(&motors.into_iter().map(|m| m.1).collect::<Vec<_>>(), &c.motors);
    let hands = r.read::<HandState>().unwrap();
    same(&hands.into_iter().map(|h| h.1).collect::<Vec<_>>(), &c.hands);
    let energies = r.read::<EnergyState>().unwrap();
    same(&energies.into_iter().map(|e| e.1).collect::<Vec<_>>(), &c.energies);
    let constraints = r.read::<ConstraintState>().unwrap();
    same(&constraints.into_iter().map(|e| e.1).collect::<Vec<_>>(), &c.constraints);
    // the ROS 2 message through its CDR schema, header stamp included
    let joints = r.read::<JointState>().unwrap();
    same(&joints.into_iter().map(|j| j.1).collect::<Vec<_>>(), &c.joints);
}

/// Typed reading of a topic the file lacks, of a message without a field the type needs, and
/// of arrays of the wrong length: errors that name the file, the topic and the field.
#[test]
fn typed_reading_errors_name_file_topic_and_field() {
    let dir = tempfile::tempdir().unwrap();
    let path = write_all(&dir.path().join("s.mcap"), &content(2));
    let r = read_recording(&path).unwrap();
    #[derive(Debug, serde::Deserialize)]
    struct Nope {}
    impl schemas::TopicMessage for Nope {
        const TOPIC: &'static str = "/nope";
    }
    let e = r.read::<Nope>().unwrap_err().to_string();
    assert!(e.contains("s.mcap") && e.contains("/nope") && e.contains("/motors"), "{e}");
    let e = r.read_sized::<MotorState>(ArraySizes { joints: 7, contacts: 0 }).unwrap_err().to_string();
    assert!(e.contains("s.mcap") && e.contains("/motors") && e.contains("current") && e.contains("expected 7"), "{e}");
    // a HandState written on /motors: the typed reader names the missing field
    let bad = dir.path().join("bad.mcap");
    let mut w = RecordingWriter::create(&bad).unwrap();
    w.write(topics::MOTORS, 0, &HandState::default()).unwrap();
    w.finish().unwrap();
    let e = read_recording(&bad).unwrap().read::<MotorState>().unwrap_err().to_string();
    assert!(e.contains("bad.mcap") && e.contains("/motors") && e.contains("missing field `current`"), "{e}");
}
