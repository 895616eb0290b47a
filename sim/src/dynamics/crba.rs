//! Composite-rigid-body algorithm for the joint-space inertia M(q): Featherstone, *Rigid Body
//! Dynamics Algorithms*, §6.2, Table 6.2 (Walker and Orin's method 3). O(n d) for a tree of
//! depth d, O(n^2) for a chain. Both triangles of M are filled.
//!
//! Two coordinate choices of the same recursion: [`crba`]/[`crba_placed`] in body coordinates
//! (Table 6.2 as printed: each column's force `F = I^c_i S_i` is carried to every ancestor by a
//! force transform), and [`crba_world`] with every quantity in world coordinates at the world
//! origin, from the world placements that forward kinematics already computed: the composite
//! inertias are plain sums, and `M_ij = S_iᵀ I^c_j S_j` is a 6-vector dot product for each
//! ancestor i of j, no transform along the chain (Table 6.2's `H_ij = S_iᵀ F` with all
//! quantities in one frame; pinocchio's `crba` likewise accumulates world-frame composite
//! inertias). The motion subspace of a revolute joint with world axis z through the world
//! point o is `S = (z, o × z)`: a rotation about z through o moves the body-fixed point at the
//! world origin with velocity `z × (0 − o) = o × z` (RBDA §2.3's Plücker motion vector); that of
//! a prismatic joint along the world direction z is `S = (0, z)` wherever its origin.

use nalgebra::{DMatrix, Vector3};

use super::data::Data;
use super::model::{JointKind, Model};
use super::spatial::{Motion, Xform};

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

/// [`crba`] in world coordinates (module docs), at the world placements already in
/// `data.x_world_body` (from `forward_kinematics` at the same q). Writes `data.m` (both
/// triangles), `data.ic` (world-frame composite inertias about the world origin) and
/// `data.s_world` (each joint's motion subspace in world coordinates).
pub fn crba_world<'d>(model: &Model, data: &'d mut Data) -> &'d DMatrix<f64> {
    let nv = model.nv;
    for (i, body) in model.bodies.iter().enumerate() {
        let x = Xform::from(&data.x_world_body[i]);
        data.ic[i] = body.inertia.to_parent_x(&x);
        let z = x.rot * body.axis.into_inner();
        data.s_world[i] = match body.kind {
            JointKind::Revolute => Motion::new(z, x.trans.cross(&z)),
            JointKind::Prismatic => Motion::new(Vector3::zeros(), z),
        };
    }
    // composite inertias, leaves first (a parent has a lower index): sums in one frame
    for i in (0..nv).rev() {
        if let Some(p) = model.bodies[i].parent {
            data.ic[p] = data.ic[p].add(&data.ic[i]);
        }
    }
    // entries of bodies on different branches of a tree stay zero
    data.m.as_mut_slice().fill(0.0); // a memset: nalgebra's `fill` went element by element
    for j in 0..nv {
        let f = data.ic[j].mul(&data.s_world[j]);
        data.m[(j, j)] = f.dot(&data.s_world[j]);
        let mut i = j;
        while let Some(p) = model.bodies[i].parent {
            i = p;
            let m_ij = f.dot(&data.s_world[i]);
            data.m[(i, j)] = m_ij;
            data.m[(j, i)] = m_ij;
        }
    }
    &data.m
}
