//! Round trips on generated recordings (proptest, 128 cases): any sequence of messages of every
//! type we write — any f64 bit pattern (NaN payloads, signed zeros, subnormals, infinities), any
//! array length, any joint names, times in order with repeats — written by `RecordingWriter` and
//! read back by the generic reader comes back identical, bit for bit, in file order, through the
//! typed reader. Times out of order (half of the cases) are refused: the reader names the first
//! message whose time goes backwards.

use proptest::prelude::*;
use schemas::{read_recording, topics, ConstraintState, EnergyState, HandState, JointState, MotorState, RecordingWriter, Vec3};

/// Any f64, by its bits (every NaN payload, ±0, subnormals, ±inf), and ordinary values.
fn any_f64() -> impl Strategy<Value = f64> {
    prop_oneof![any::<u64>().prop_map(f64::from_bits), -1e6f64..1e6]
}

fn floats(max: usize) -> impl Strategy<Value = Vec<f64>> {
    prop::collection::vec(any_f64(), 0..max)
}

fn names(max: usize) -> impl Strategy<Value = Vec<String>> {
    prop::collection::vec("[a-zA-Z0-9_/ é]{0,12}", 0..max)
}

fn motor() -> impl Strategy<Value = MotorState> {
    (any_f64(), floats(12), floats(12), floats(12), floats(12), floats(12), names(12)).prop_map(
        |(time, current, voltage, back_emf, electric_power, torque, name)| MotorState { time, current, voltage, back_emf, electric_power, torque, name },
    )
}

fn vec3() -> impl Strategy<Value = Vec3> {
    (any_f64(), any_f64(), any_f64()).prop_map(|(x, y, z)| Vec3 { x, y, z })
}

fn hand() -> impl Strategy<Value = HandState> {
    (any_f64(), vec3(), vec3(), vec3(), any_f64()).prop_map(|(time, actual, desired, error, error_norm)| HandState { time, actual, desired, error, error_norm })
}

fn energy() -> impl Strategy<Value = EnergyState> {
    (any_f64(), floats(12), floats(12), prop::collection::vec(any_f64(), 10), names(12)).prop_map(|(time, link_work, electric_energy, s, name)| EnergyState {
        time,
        link_work,
        electric_energy,
        link_work_total: s[0],
        electric_energy_total: s[1],
        kinetic: s[2],
        potential: s[3],
        magnetic: s[4],
        resistive_loss: s[5],
        friction_loss: s[6],
        balance_residual: s[7],
        gear_friction_loss: s[8],
        name,
    })
}

fn joints() -> impl Strategy<Value = JointState> {
    (0u64..1_000_000_000_000, "[a-z][a-z0-9_]{0,8}", prop::collection::vec("[a-zA-Z0-9_/ é]{0,12}", 0..8), floats(8), floats(8), floats(8)).prop_map(
        |(stamp_ns, frame_id, name, position, velocity, effort)| JointState { stamp_ns, frame_id, name, position, velocity, effort },
    )
}

fn constraints() -> impl Strategy<Value = ConstraintState> {
    (any_f64(), floats(4), floats(4), floats(4), names(4))
        .prop_map(|(time, normal_force, position, velocity, name)| ConstraintState { time, normal_force, position, velocity, name })
}

/// The Debug text distinguishes every value we care about (-0.0, NaN) and equals for equal bits
/// except NaN payloads, which the bits check below covers.
fn same<T: std::fmt::Debug>(a: &[T], b: &[T]) -> bool {
    format!("{a:?}") == format!("{b:?}")
}

fn bits(v: &[f64]) -> Vec<u64> {
    v.iter().map(|x| x.to_bits()).collect()
}


proptest! {
    #![proptest_config(ProptestConfig::with_cases(128))]

    #[test]
    fn every_message_round_trips_bit_for_bit(
        n in 0usize..24,
        mut times in prop::collection::vec(0u64..5_000_000_000, 24),
        ordered in any::<bool>(),
        m in prop::collection::vec(motor(), 24),
        h in prop::collection::vec(hand(), 24),
        e in prop::collection::vec(energy(), 24),
        j in prop::collection::vec(joints(), 24),
        c in prop::collection::vec(constraints(), 24),
        chunk in prop_oneof![Just(None), (256u64..8192).prop_map(Some)],
    ) {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("r.mcap");
        let mut w = match chunk {
            Some(k) => RecordingWriter::create_with_chunk_size(&path, k),
            None => RecordingWriter::create(&path),
        }.unwrap();
        // repeated times stay (equal times are in order)
        times.iter_mut().for_each(|t| *t -= *t % 250_000_000);
        if ordered {
            times[..n].sort();
        }
        let times = &times[..n];
        for k in 0..n {
            w.write(topics::MOTORS, times[k], &m[k]).unwrap();
            w.write(topics::HAND, times[k], &h[k]).unwrap();
            w.write(topics::ENERGY, times[k], &e[k]).unwrap();
            w.write(topics::JOINT_STATES, times[k], &j[k]).unwrap();
            w.write(topics::CONSTRAINTS, times[k], &c[k]).unwrap();
        }
        w.finish().unwrap();
        // the first message of the file whose time is before its channel's previous one
        if let Some(k) = (1..n).find(|&k| times[k] < times[k - 1]) {
            match read_recording(&path) {
                Err(schemas::Error::TimeBackwards { topic, index, log_time_ns, previous_ns, .. }) => {
                    prop_assert_eq!((topic.as_str(), index), (topics::MOTORS, k));
                    prop_assert_eq!((log_time_ns, previous_ns), (times[k], times[k - 1]));
                }
                other => prop_assert!(false, "time goes backwards at #{}, but the reader gave {:?}", k, other.map(|_| ())),
            }
            return Ok(());
        }
        let rec = read_recording(&path).unwrap();
        // (an empty recording has the channels of nothing)
        if n == 0 {
            prop_assert!(rec.messages(topics::MOTORS).is_none());
            return Ok(());
        }
        let got_m: Vec<MotorState> = rec.read::<MotorState>().unwrap().into_iter().map(|x| x.1).collect();
        let want_m = &m[..n];
        prop_assert!(same(&got_m, want_m));
        for (a, b) in got_m.iter().zip(want_m) {
            prop_assert_eq!(bits(&a.current), bits(&b.current));
            prop_assert_eq!(bits(&a.torque), bits(&b.torque));
        }
        prop_assert!(same(&rec.read::<HandState>().unwrap().into_iter().map(|x| x.1).collect::<Vec<_>>(), &h[..n]));
        let got_e: Vec<EnergyState> = rec.read::<EnergyState>().unwrap().into_iter().map(|x| x.1).collect();
        prop_assert!(same(&got_e, &e[..n]));
        prop_assert!(same(&rec.read::<JointState>().unwrap().into_iter().map(|x| x.1).collect::<Vec<_>>(), &j[..n]));
        prop_assert!(same(&rec.read::<ConstraintState>().unwrap().into_iter().map(|x| x.1).collect::<Vec<_>>(), &c[..n]));
        let got_t: Vec<u64> = rec.read::<MotorState>().unwrap().iter().map(|x| schemas::to_log_time(x.0)).collect();
        prop_assert_eq!(got_t, times.to_vec());
    }
}
