//! Projection of the state back onto the constraint manifold after a step: positions onto
//! C(q) = 0 by Gauss–Newton with the minimum-norm correction `Δq = −J_cᵀ (J_c J_cᵀ)⁻¹ C`
//! (iterated to |C| ≤ 1e-13 m, at most 5 times), then velocities onto `J_c q̇ = 0` by
//! `Δq̇ = −J_cᵀ (J_c J_cᵀ)⁻¹ J_c q̇` (Hairer, Lubich & Wanner, *Geometric Numerical
//! Integration*, §IV.4; Ascher et al., "Stabilization of constrained mechanical systems with
//! DAEs and invariant manifolds", 1995). Redundant rows are regularised as in the force solve (`dynamics/spd.rs`).

use crate::dynamics::constraints::{constraint_jacobian, PointOnPlane};
use crate::dynamics::kinematics::{forward_kinematics, forward_velocities};
use crate::dynamics::spd::solve_regularized;
use crate::error::DynamicsError;

use super::arm::ArmSystem;
use super::workspace::ProjectionScratch;

/// `J Jᵀ` into `p.jjt` (no temporary).
fn form_jjt(p: &mut ProjectionScratch, nc: usize) {
    for a in 0..nc {
        for b in 0..nc {
            p.jjt[(a, b)] = p.jac.row(a).dot(&p.jac.row(b));
        }
    }
}

/// Solve `J Jᵀ x = rhs` in place, regularised like the force solve when J Jᵀ is singular.
fn solve_jjt(p: &mut ProjectionScratch, t: f64, nc: usize, contacts: &[PointOnPlane]) -> Result<(), DynamicsError> {
    form_jjt(p, nc);
    match solve_regularized(&p.jjt, &mut p.work, &mut p.rhs) {
        Some(_) => Ok(()),
        None => Err(DynamicsError::SingularConstraints { t, constraints: format!("the projection onto the constraints: {}", constraint_names(contacts).join(", ")) }),
    }
}

/// The constraints' names, for a singular projection's error (an error path only).
fn constraint_names(contacts: &[PointOnPlane]) -> Vec<&str> {
    contacts.iter().map(|c| c.name.as_str()).collect()
}

impl ArmSystem<'_> {
    /// Project `y` onto C = 0, Ċ = 0. Returns whether it changed.
    pub fn project_onto_constraints(&mut self, t: f64, y: &mut [f64]) -> Result<bool, DynamicsError> {
        let nc = self.contacts.len();
        if nc == 0 {
            return Ok(false);
        }
        let l = self.layout;
        let model = &self.scene.model;
        let (p, data) = (&mut self.ws.projection, &mut self.ws.data);
        let mut changed = false;
        for _ in 0..5 {
            let q = &y[l.q()];
            forward_kinematics(model, data, q);
            let mut worst = 0.0f64;
            for (k, c) in self.contacts.iter().enumerate() {
                p.rhs[k] = c.position(data);
                worst = worst.max(p.rhs[k].abs());
            }
            if worst <= 1e-13 {
                break;
            }
            forward_velocities(model, data, &y[l.qd()]);
            constraint_jacobian(model, data, &self.contacts, &mut p.jac, &mut p.jdqd);
            solve_jjt(p, t, nc, &self.contacts)?;
            // Δq = −Jᵀ x
            for j in 0..l.nv {
                let dq: f64 = (0..nc).map(|k| p.jac[(k, j)] * p.rhs[k]).sum();
                y[l.q().start + j] -= dq;
            }
            changed = true;
        }
        // velocities at the projected positions
        forward_kinematics(model, data, &y[l.q()]);
        forward_velocities(model, data, &y[l.qd()]);
        constraint_jacobian(model, data, &self.contacts, &mut p.jac, &mut p.jdqd);
        let mut worst = 0.0f64;
        for k in 0..nc {
            p.rhs[k] = (0..l.nv).map(|j| p.jac[(k, j)] * y[l.qd().start + j]).sum();
            worst = worst.max(p.rhs[k].abs());
        }
        if worst > 1e-13 {
            solve_jjt(p, t, nc, &self.contacts)?;
            for j in 0..l.nv {
                let dv: f64 = (0..nc).map(|k| p.jac[(k, j)] * p.rhs[k]).sum();
                y[l.qd().start + j] -= dv;
            }
            changed = true;
        }
        Ok(changed)
    }
}

impl ArmSystem<'_> {
    /// A hybrid run's projection (same method, HLW §IV.4): positions onto g = 0 for the
    /// contacts in touch (and the bilateral ones), then velocities onto ġ = 0 for those and
    /// v_t = 0 for the sticking ones; minimum-norm corrections `−Wᵀ (W Wᵀ)⁻¹ r`.
    pub fn project_onto_active_rows(&mut self, t: f64, y: &mut [f64]) -> Result<bool, DynamicsError> {
        use crate::dynamics::contact::rows::contact_rows_where;
        use crate::dynamics::contact::solve::{solve_active, ActiveRow, RowForce};
        use crate::dynamics::contact::ContactMode;
        let l = self.layout;
        let model = &self.scene.model;
        let data = &mut self.ws.data;
        let Some(h) = self.hybrid.as_mut() else { return Ok(false) };
        let held = |m: ContactMode| matches!(m, ContactMode::Sticking | ContactMode::Sliding | ContactMode::Bilateral);
        if !h.state.mode.iter().any(|&m| held(m)) {
            return Ok(false);
        }
        // the error names the contacts whose rows are projected on (review F6)
        let singular = |contacts: &[crate::dynamics::contact::Contact], mode: &[ContactMode]| {
            let names: Vec<&str> = contacts.iter().zip(mode).filter(|(_, &m)| held(m)).map(|(c, _)| c.name()).collect();
            DynamicsError::SingularConstraints { t, constraints: format!("the projection onto the contacts in touch: {}", names.join(", ")) }
        };
        let mut changed = false;
        for pass in 0..6 {
            let q = &y[l.q()];
            forward_kinematics(model, data, q);
            forward_velocities(model, data, &y[l.qd()]);
            // the rows of the contacts in touch only (a separated candidate is no row here)
            let mode = &h.state.mode;
            contact_rows_where(model, data, &h.contacts, &mut h.cd.rows, |k| held(mode[k]));
            let r = &h.cd.rows;
            h.proj_rows.clear();
            let mut worst = 0.0f64;
            for k in 0..h.contacts.len() {
                if held(h.state.mode[k]) {
                    worst = worst.max(r.gap[k].abs());
                    h.proj_rows.push(ActiveRow { row: 3 * k, force: RowForce::Same, extra: r.gap[k] - r.bias[3 * k] });
                }
            }
            if worst <= 1e-13 || pass == 5 {
                break;
            }
            solve_active(&h.eye, &h.ones, &h.zeros, r, &h.proj_rows, &mut h.cd.scratch, &mut h.proj_dx).map_err(|_| singular(&h.contacts, &h.state.mode))?;
            for j in 0..l.nv {
                y[l.q().start + j] += h.proj_dx[j];
            }
            changed = true;
        }
        // velocities at the projected positions (rows of the last pass)
        let r = &h.cd.rows;
        h.proj_rows.clear();
        let mut worst = 0.0f64;
        for k in 0..h.contacts.len() {
            let m = h.state.mode[k];
            if held(m) {
                let axes = if m == ContactMode::Sticking { 0..3 } else { 0..1 };
                for a in axes {
                    let v = r.vel[3 * k + a];
                    worst = worst.max(v.abs());
                    h.proj_rows.push(ActiveRow { row: 3 * k + a, force: RowForce::Same, extra: v - r.bias[3 * k + a] });
                }
            }
        }
        if worst > 1e-13 {
            solve_active(&h.eye, &h.ones, &h.zeros, r, &h.proj_rows, &mut h.cd.scratch, &mut h.proj_dx).map_err(|_| singular(&h.contacts, &h.state.mode))?;
            for j in 0..l.nv {
                y[l.qd().start + j] += h.proj_dx[j];
            }
            changed = true;
        }
        Ok(changed)
    }
}
