//! Composite-rigid-body algorithm for the joint-space inertia M(q): Featherstone, *Rigid Body
//! Dynamics Algorithms*, §6.2, Table 6.2 (Walker and Orin's method 3). O(n d) for a tree of
//! depth d, O(n^2) for a chain. Both triangles of M are filled.

use nalgebra::{DMatrix, Vector3};

use super::data::Data;
use super::model::Model;
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
    data.m.fill(0.0);
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
        let s_i = Motion::new(model.bodies[i].axis.into_inner(), Vector3::zeros());
        let mut f = data.ic[i].mul(&s_i);
        data.m[(i, i)] = s_i.w.dot(&f.n);
        let mut j = i;
        while let Some(p) = model.bodies[j].parent {
            f = f.to_parent_x(&data.xm_parent_body[j]);
            j = p;
            let m_ij = model.bodies[j].axis.dot(&f.n);
            data.m[(i, j)] = m_ij;
            data.m[(j, i)] = m_ij;
        }
    }
    &data.m
}
