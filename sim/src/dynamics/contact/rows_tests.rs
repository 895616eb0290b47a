//! Tests of `rows.rs`: the fill that zeroes only the rows it must. Split from `tests.rs`
//! (file size).

use nalgebra::{Unit, Vector3};

use super::{contact_rows, contact_rows_only, contact_rows_where, ContactRows};
use crate::dynamics::contact::shape::ContactShape;
use crate::dynamics::contact::{Contact, ContactModel};
use crate::dynamics::constraints::PointOnPlane;
use crate::dynamics::data::Data;
use crate::dynamics::kinematics::{forward_kinematics, forward_velocities, BodyPoint};
use crate::dynamics::samples::{random_chain, SplitMix64};

/// The rows' fill that zeroes only what it must (a contact's rows zero while it has none,
/// `ContactRows::zero`) leaves `jac`, the biases, gaps and velocities bit for bit as a fill
/// into freshly zeroed rows does, over a sequence of fills in which each of 3 contacts gains
/// and loses its rows (touching → separated → touching, as at events), through each of the
/// three fills (`contact_rows`, `contact_rows_where`, `contact_rows_only`), on a random
/// 6-joint chain at random states. Exact equality: the same operations on the same inputs.
#[test]
fn rows_kept_zero_equal_a_fill_from_zero() {
    let model = random_chain(6, 91);
    let nv = model.nv;
    let mut rng = SplitMix64(17);
    let contacts: Vec<Contact> = (0..3)
        .map(|k| {
            let plane = PointOnPlane {
                name: format!("c{k}"),
                point: BodyPoint { body: Some(2 * k + 1), p_body: Vector3::new(0.05, 0.1 * k as f64, 0.2) },
                normal_world: Unit::new_normalize(rng.unit_vector()),
                offset: 0.1,
            };
            Contact::new(plane, ContactModel::Unilateral { restitution: 0.0, friction: 0.5 })
        })
        .collect();
    let mut data = Data::new(&model);
    let mut kept = ContactRows::new(nv, 3);
    for step in 0..40usize {
        let q: Vec<f64> = rng.vector(nv, -1.5, 1.5).to_vec();
        let qd: Vec<f64> = rng.vector(nv, -1.0, 1.0).to_vec();
        forward_kinematics(&model, &mut data, &q);
        forward_velocities(&model, &mut data, &qd);
        let pattern = (step * 5 + step / 3) % 8; // bit k: contact k has rows
        let has = |k: usize| pattern & (1 << k) != 0;
        let mut fresh = ContactRows::new(nv, 3);
        // what a fill leaves of the gaps and velocities it does not compute is the last fill's
        fresh.gap.clone_from(&kept.gap);
        fresh.vel.clone_from(&kept.vel);
        match step % 3 {
            0 => {
                contact_rows(&model, &data, &contacts, &mut kept);
                contact_rows(&model, &data, &contacts, &mut fresh);
            }
            1 => {
                contact_rows_where(&model, &data, &contacts, &mut kept, has);
                contact_rows_where(&model, &data, &contacts, &mut fresh, has);
            }
            _ => {
                contact_rows_only(&model, &data, &contacts, &mut kept, has);
                contact_rows_only(&model, &data, &contacts, &mut fresh, has);
            }
        }
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&kept.jac), bits(&fresh.jac), "step {step}, rows of {pattern:03b}: J");
        assert_eq!(bits(&kept.bias), bits(&fresh.bias), "step {step}: J̇ q̇");
        assert_eq!(bits(&kept.gap), bits(&fresh.gap), "step {step}: gaps");
        assert_eq!(bits(&kept.vel), bits(&fresh.vel), "step {step}: velocities");
        assert!((0..3).any(|k| kept.row(3 * k).iter().any(|&x| x != 0.0)) || pattern == 0 && step % 3 != 0, "step {step}: some rows filled");
    }
}

/// [`Contact::touch_moving`] (no `J̇ q̇`) gives [`Contact::touch`]'s point, gap and velocity bit
/// for bit, for a point, a sphere and a rim, at 20 random states of a random 5-joint chain:
/// what `contact_gaps_where` writes for a separated candidate is what it wrote before.
#[test]
fn a_touch_without_its_bias_has_the_same_point_gap_and_velocity() {
    let model = random_chain(5, 23);
    let nv = model.nv;
    let mut rng = SplitMix64(29);
    let plane = PointOnPlane {
        name: "pad".into(),
        point: BodyPoint { body: Some(nv - 1), p_body: Vector3::new(0.1, -0.05, 0.2) },
        normal_world: Unit::new_normalize(Vector3::new(0.2, -0.1, 1.0)),
        offset: -0.3,
    };
    let shapes = [ContactShape::Point, ContactShape::Sphere { radius: 0.07 }, ContactShape::Rim { radius: 0.07, axis: Vector3::new(0.3, -0.8, 0.5).normalize() }];
    let mut data = Data::new(&model);
    for shape in shapes {
        let c = Contact::new(plane.clone(), ContactModel::Unilateral { restitution: 0.0, friction: 0.5 }).with_shape(shape);
        for _ in 0..20 {
            let q: Vec<f64> = rng.vector(nv, -1.5, 1.5).to_vec();
            let qd: Vec<f64> = rng.vector(nv, -1.0, 1.0).to_vec();
            forward_kinematics(&model, &mut data, &q);
            forward_velocities(&model, &mut data, &qd);
            let (full, moving) = (c.touch(&data), c.touch_moving(&data));
            let bits = |v: &Vector3<f64>| [v.x.to_bits(), v.y.to_bits(), v.z.to_bits()];
            assert_eq!(bits(&full.point), bits(&moving.point), "{shape:?}: point");
            assert_eq!(full.gap.to_bits(), moving.gap.to_bits(), "{shape:?}: gap");
            assert_eq!(bits(&full.velocity), bits(&moving.velocity), "{shape:?}: velocity");
            assert_eq!(moving.bias, Vector3::zeros(), "{shape:?}: no bias");
            assert!(full.bias.norm() > 0.0, "{shape:?}: the full touch has one (the case is not trivial)");
        }
    }
}
