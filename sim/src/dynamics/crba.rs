//! Composite-rigid-body algorithm for the joint-space inertia M(q): Featherstone, *Rigid Body
//! Dynamics Algorithms*, §6.2, Table 6.2 (Walker and Orin's method 3). O(n d) for a tree of
//! depth d, O(n^2) for a chain. Both triangles of M are filled.
//!
//! Two coordinate choices of the same recursion:
//! - [`crba`]/[`crba_placed`] in body coordinates (Table 6.2 as printed: each column's force
//!   `F = I^c_i S_i` is carried to every ancestor by a force transform);
//! - [`crba_world`] in world-aligned coordinates, from the world placements that forward
//!   kinematics already computed: every quantity of joint i has the world's axes and joint i's
//!   origin `o_i` as its reference point (pinocchio's `LOCAL_WORLD_ALIGNED` frame). A body's
//!   inertia is only rotated; a child's composite inertia is carried to its parent's origin by a
//!   translation (RBDA eq 2.66 with R = 1); a revolute joint's motion subspace is `S = (z, 0)`
//!   and a prismatic joint's `S = (0, z)` at their own origins; and `M_ij = S_iᵀ F_j` needs only
//!   F_j's moment moved from o_j to o_i, `n + (o_j − o_i) × f` (RBDA eq 2.28), no rotation along
//!   the chain.
//!
//! Why not about the world origin (as this function did before issue 24, and as
//! `I_o = I_c + m [c]×[c]×ᵀ` suggests): an inertia about a point far from the body carries
//! `m |c|²` terms that cancel in the small entries of a distal joint's rows, and M lost up to
//! two digits on published URDFs (max |ΔM_ij| / √(M_ii M_jj) against the body-frame CRBA up to
//! 5e-13, median 7.8e-15, on the 40 example-robot-data URDFs that load; q̈ up to 2e-13). About
//! each joint's own origin the lever arms are the subtree's size, as in body coordinates:
//! 7.6e-15 at worst, median 2.0e-15, and 0.6–0.85× the time of the world-origin version
//! (the rotation-only transform and S = (z, 0) save more than the moment shifts cost).

use nalgebra::{DMatrix, Vector3};

use super::data::Data;
use super::model::{JointKind, Model};
use super::spatial::Motion;

/// Joint-space inertia of the rigid bodies (nv x nv, kg m^2), stored in `data.m`, symmetric.
/// Also writes `data.x_parent_body` and `data.ic`.
pub fn crba<'d>(model: &Model, data: &'d mut Data, q: &[f64]) -> &'d DMatrix<f64> {
    assert_eq!(q.len(), model.nv, "q: expected nv");
    for i in 0..model.nv {
        let x = model.joint_placement(i, q[i]);
        data.x_parent_body[i] = x;
        data.xm_parent_body[i] = (&x).into();
    }
    crba_placed(model, data)
}

/// [`crba`] at the placements already in `data.xm_parent_body`.
pub fn crba_placed<'d>(model: &Model, data: &'d mut Data) -> &'d DMatrix<f64> {
    let nv = model.nv;
    // entries of bodies on different branches of a tree stay zero
    data.m.as_mut_slice().fill(0.0);
    for (i, body) in model.bodies.iter().enumerate() {
        data.ic[i] = body.inertia;
    }
    // composite inertias, leaves first (a parent has a lower index)
    for i in (0..nv).rev() {
        if let Some(p) = model.bodies[i].parent {
            let moved = data.ic[i].to_parent_x(&data.xm_parent_body[i]);
            data.ic[p] = data.ic[p].add(&moved);
        }
    }
    for i in 0..nv {
        let s_i = model.bodies[i].subspace();
        let mut f = data.ic[i].mul(&s_i);
        data.m[(i, i)] = match model.bodies[i].kind {
            JointKind::Revolute => s_i.w.dot(&f.n),
            JointKind::Prismatic => s_i.v.dot(&f.f),
        };
        let mut j = i;
        while let Some(p) = model.bodies[j].parent {
            f = f.to_parent_x(&data.xm_parent_body[j]);
            j = p;
            let m_ij = match model.bodies[j].kind {
                JointKind::Revolute => model.bodies[j].axis.dot(&f.n),
                JointKind::Prismatic => model.bodies[j].axis.dot(&f.f),
            };
            data.m[(i, j)] = m_ij;
            data.m[(j, i)] = m_ij;
        }
    }
    &data.m
}

/// [`crba`] in world-aligned coordinates (module docs), at the world placements already in
/// `data.x_world_body` (from `forward_kinematics` at the same q). Writes `data.m` (both
/// triangles), `data.ic` (composite inertias with world axes about each joint's origin) and
/// `data.s_world` (each joint's motion subspace with world axes at its own origin).
pub fn crba_world<'d>(model: &Model, data: &'d mut Data) -> &'d DMatrix<f64> {
    let nv = model.nv;
    for (i, body) in model.bodies.iter().enumerate() {
        let rot = *data.x_world_body[i].rotation.to_rotation_matrix().matrix();
        data.ic[i] = body.inertia.rotated(&rot);
        let z = rot * body.axis.into_inner();
        data.s_world[i] = match body.kind {
            JointKind::Revolute => Motion::new(z, Vector3::zeros()),
            JointKind::Prismatic => Motion::new(Vector3::zeros(), z),
        };
    }
    // composite inertias, leaves first (a parent has a lower index): each child's moved from
    // its joint's origin to its parent's (a translation: the axes are the world's in both)
    for i in (0..nv).rev() {
        if let Some(p) = model.bodies[i].parent {
            let o_p_i = data.x_world_body[i].translation.vector - data.x_world_body[p].translation.vector;
            data.ic[p] = data.ic[p].add(&data.ic[i].translated(&o_p_i));
        }
    }
    // entries of bodies on different branches of a tree stay zero
    data.m.as_mut_slice().fill(0.0); // a memset: nalgebra's `fill` went element by element
    for j in 0..nv {
        // F = I^c_j S_j about o_j; its moment about an ancestor's origin o_i is n + (o_j − o_i) × f
        let f = data.ic[j].mul(&data.s_world[j]);
        data.m[(j, j)] = f.dot(&data.s_world[j]);
        let o_j = data.x_world_body[j].translation.vector;
        let mut i = j;
        while let Some(p) = model.bodies[i].parent {
            i = p;
            let m_ij = match model.bodies[i].kind {
                JointKind::Revolute => {
                    let r = o_j - data.x_world_body[i].translation.vector;
                    data.s_world[i].w.dot(&(f.n + r.cross(&f.f)))
                }
                JointKind::Prismatic => data.s_world[i].v.dot(&f.f),
            };
            data.m[(i, j)] = m_ij;
            data.m[(j, i)] = m_ij;
        }
    }
    &data.m
}
