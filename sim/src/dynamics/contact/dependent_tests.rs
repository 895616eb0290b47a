//! The onset of a group of contacts with rows dependent across contacts ([`super`]) on the
//! paper arm: the friction's anchor, the forces, the onset's excess and q̈ as functions of the
//! state (`forward::onset_anchors`, issue 23 item 6, the joint-3 crawl).

/// The onset of a dependent group is a function of the state (`forward::onset_anchors`,
/// issue 23 item 6, the joint-3 crawl): the paper arm at its start pose with elbow4 at joint 3's
/// origin (rows of rank 2, moved by joints 1 and 2 only) and elbow7 at joint 7's, one
/// group; the currents along those of the common onset (joint 9 : joint 10 : joint 1 ≈
/// 1 : −1.52 : 0.0078) scaled to 1e-3 past the group's stick (bisection on its margin).
/// There elbow7 binds while elbow4 is inside its own cone by more than 0.1 N, so the
/// group program's maximiser is not unique. Both slide in an onset; at seven states 1e-12
/// apart (q_j + 1e-12 rad, a current × (1 + 1e-12)) the anchors, f_n, the onset's excess and
/// q̈ agree with the first state's to 1e-9 (rad, N, N, relative): a smooth function moves
/// by ~1e-12 times a slope of O(1–100) there; elbow4's anchor is the event's direction. The
/// barrier's iterate, the old anchor, moved by 8.1e-3 rad between such states (checked).
#[test]
fn a_dependent_groups_onset_is_a_continuous_function_of_the_state() {
    use crate::dynamics::contact::forward::{prepare, solve_modes, ContactData, ContactState};
    use crate::dynamics::contact::{Contact, ContactMode, ContactModel};
    use crate::dynamics::constraints::PointOnPlane;
    use crate::dynamics::data::Data;
    use crate::dynamics::forward::{ForwardData, Plant};
    use crate::dynamics::kinematics::{body_point, forward_kinematics};
    use crate::dynamics::model::Model;
    use crate::dynamics::motor::{Drives, MotorParams};
    use nalgebra::{Unit, Vector3};

    let model = Model::from_urdf(crate::scene::PAPER_URDF, "paper_arm.urdf", Vector3::new(0.0, 0.0, -9.81)).expect("paper arm");
    let nv = model.nv;
    let motor = MotorParams { torque_constant: 0.203, resistance: 1.1, inductance: 0.0017, rotor_inertia: 0.000164, gear_ratio: 3.0, gear_damping: 0.01 };
    let drives = Drives::new(&vec![motor; nv], &vec![0.5; nv]);
    let plant = Plant { model: &model, drives: &drives, contacts: &[], mass_matrix: Default::default(), solver: Default::default(), stabilization: Default::default() };
    let h = std::f64::consts::FRAC_PI_4;
    let q0 = [0.0, h, 2.0 * h, -2.0 * h, h, h, -2.0 * h, h, -h, h];
    let mut data = Data::new(&model);
    forward_kinematics(&model, &mut data, &q0);
    let contacts: Vec<Contact> = [("elbow4", "link3"), ("elbow7", "link7")]
        .iter()
        .map(|&(name, link)| {
            let plane = |offset| PointOnPlane { name: name.into(), point: body_point(&model, link, Vector3::zeros()).expect("link"), normal_world: Unit::new_normalize(Vector3::z()), offset };
            let z = Contact::new(plane(0.0), ContactModel::Unilateral { restitution: 0.0, friction: 0.5 }).gap(&data);
            Contact::new(plane(z), ContactModel::Unilateral { restitution: 0.0, friction: 0.5 })
        })
        .collect();
    let (mut fd, mut cd) = (ForwardData::new(nv, 2), ContactData::new(nv, 2));
    let qd = vec![0.0; nv];
    let currents = |scale: f64| -> Vec<f64> { (0..nv).map(|j| scale * [0.0078, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, -1.52][j]).collect() };
    let mut solve = |q: &[f64], cur: &[f64], state: &ContactState, fd: &mut ForwardData, cd: &mut ContactData| {
        prepare(&plant, &contacts, &mut data, fd, cd, 0.0, q, &qd, cur).expect("prepare");
        solve_modes(&contacts, state, Default::default(), fd, cd).expect("solve");
    };
    let stick = ContactState { mode: vec![ContactMode::Sticking; 2], slip: vec![[1.0, 0.0]; 2], onset: vec![None; 2] };
    let (mut lo, mut hi) = (0.0, 4.0);
    solve(&q0, &currents(hi), &stick, &mut fd, &mut cd);
    assert!(cd.margin[0] < 0.0, "the stick breaks by 4x the onset's currents: {:?}", cd.margin);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        solve(&q0, &currents(mid), &stick, &mut fd, &mut cd);
        if cd.margin[0] >= 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let cur0 = currents(hi * (1.0 + 1e-3));
    solve(&q0, &cur0, &stick, &mut fd, &mut cd);
    let own = |k: usize, cd: &ContactData| 0.5 * cd.f_n[k] - cd.f_t[k][0].hypot(cd.f_t[k][1]);
    assert!(cd.margin[0] == cd.margin[1] && cd.margin[0] < 0.0, "one group, broken: {:?}", cd.margin);
    assert!(own(0, &cd) > 0.1 && (own(1, &cd) - cd.margin[1]).abs() <= 1e-9, "elbow4 inside its cone ({} N), elbow7 binding ({} N)", own(0, &cd), own(1, &cd));
    // the event's directions: the sticking forces' impending ones
    let slip: Vec<[f64; 2]> = (0..2).map(|k| {
        let (f, m) = (cd.f_t[k], cd.f_t[k][0].hypot(cd.f_t[k][1]));
        [-f[0] / m, -f[1] / m]
    }).collect();
    let onset = ContactState { mode: vec![ContactMode::Sliding; 2], slip: slip.clone(), onset: vec![Some([1.0, 0.0]); 2] };
    let mut states: Vec<(Vec<f64>, Vec<f64>)> = vec![(q0.to_vec(), cur0.clone())];
    for j in [0, 1, 2, 5, 8, 9] {
        let mut q = q0.to_vec();
        q[j] += 1e-12;
        states.push((q, cur0.clone()));
    }
    let mut cur = cur0.clone();
    cur[9] *= 1.0 + 1e-12;
    states.push((q0.to_vec(), cur));
    // anchors, f_n, the onset's excess, q̈
    type Outputs = (Vec<[f64; 2]>, Vec<f64>, Vec<f64>, Vec<f64>);
    let mut first: Option<Outputs> = None;
    for (q, cur) in &states {
        solve(q, cur, &onset, &mut fd, &mut cd);
        let now = (cd.anchor.clone(), cd.f_n.clone(), cd.onset_excess.clone(), fd.qdd.as_slice()[..nv].to_vec());
        assert!(now.2.iter().all(|e| *e > 0.0), "the stick stays broken: excess {:?}", now.2);
        assert_eq!(now.0[0], slip[0], "elbow4, inside its own cone, keeps the event's direction");
        if let Some((a, f_n, e, qdd)) = &first {
            for k in 0..2 {
                let da = (a[k][0] - now.0[k][0]).hypot(a[k][1] - now.0[k][1]);
                assert!(da <= 1e-9, "contact {k}: the anchor moves by {da:e} rad over 1e-12 of the state");
                assert!((f_n[k] - now.1[k]).abs() <= 1e-9 && (e[k] - now.2[k]).abs() <= 1e-9, "contact {k}: f_n {} → {}, excess {} → {}", f_n[k], now.1[k], e[k], now.2[k]);
            }
            for (x, y) in qdd.iter().zip(&now.3) {
                assert!((x - y).abs() <= 1e-9 * (1.0 + x.abs()), "q̈ {x} → {y}");
            }
        } else {
            first = Some(now);
        }
    }
}
