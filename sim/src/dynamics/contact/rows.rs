//! The rows of each contact: gap `g = n · p − d` (p the touching point of the contact's shape,
//! `shape.rs`), the normal row `J_n = nᵀ J_p` and the
//! tangential rows `J_t = [t1ᵀ J_p; t2ᵀ J_p]` (J_p the point's world linear-velocity Jacobian),
//! their biases `J̇ q̇` along n, t1, t2, and the velocities `ġ = J_n q̇`, `v_t = J_t q̇`
//! (Pfeiffer & Glocker, *Multibody Dynamics with Unilateral Contacts*, 1996, §4; the point
//! kinematics of `dynamics/kinematics.rs`, Featherstone RBDA §2.7).

use super::Contact;
use crate::dynamics::{Data, Model};

/// Rows of all contacts of a run, preallocated for nc contacts and nv joints. Row `3k` is
/// contact k's normal, `3k + 1` and `3k + 2` its tangents t1, t2 (row-major, nv columns).
#[derive(Clone, Debug)]
pub struct ContactRows {
    pub nv: usize,
    /// `3 nc x nv`, row-major.
    pub jac: Vec<f64>,
    /// `J̇ q̇` along n, t1, t2 (3 nc), m/s^2.
    pub bias: Vec<f64>,
    /// Gap g (nc), m.
    pub gap: Vec<f64>,
    /// `ġ, v_t1, v_t2` (3 nc), m/s.
    pub vel: Vec<f64>,
    /// Whether contact k's three rows of `jac` are all zero (as `new` makes them, and as a
    /// fill without its rows leaves them): such rows are not zeroed again, so a separated
    /// candidate costs no write per evaluation (issue 24 item 2). Only this module writes `jac`.
    zero: Vec<bool>,
}

impl ContactRows {
    pub fn new(nv: usize, nc: usize) -> Self {
        ContactRows { nv, jac: vec![0.0; 3 * nc * nv], bias: vec![0.0; 3 * nc], gap: vec![0.0; nc], vel: vec![0.0; 3 * nc], zero: vec![true; nc] }
    }

    /// Row `r` (`3k + axis`).
    pub fn row(&self, r: usize) -> &[f64] {
        &self.jac[r * self.nv..(r + 1) * self.nv]
    }

    /// `row_r · x`.
    pub fn dot(&self, r: usize, x: &[f64]) -> f64 {
        self.row(r).iter().zip(x).map(|(a, b)| a * b).sum()
    }

    /// The slip velocity `[v_t1, v_t2]` of contact k, m/s.
    pub fn slip(&self, k: usize) -> [f64; 2] {
        [self.vel[3 * k + 1], self.vel[3 * k + 2]]
    }
}

/// Fill `rows` at the state of `data` (needs `forward_kinematics` and `forward_velocities`).
/// The normal row's formulas are those of `constraints::constraint_rows` (same operations).
pub fn contact_rows(model: &Model, data: &Data, contacts: &[Contact], rows: &mut ContactRows) {
    contact_rows_where(model, data, contacts, rows, |_| true);
}

/// [`contact_rows`] with the rows (`J`, `J̇ q̇`) of contact k only where `rows_of(k)`; the
/// others get their gap and velocities (`g`, `ġ`, `v_t`: what their event functions and the
/// recorded outputs read) and zero rows and biases. For the right-hand side of a hybrid run,
/// where a separated contact adds no force (issue 24 item 2: a candidate that does not touch
/// costs its touching point, not three Jacobian rows).
pub fn contact_rows_where(model: &Model, data: &Data, contacts: &[Contact], rows: &mut ContactRows, rows_of: impl Fn(usize) -> bool) {
    fill_rows(model, data, contacts, rows, rows_of, true);
}

/// [`contact_rows_where`] that does not touch the other contacts at all: zero rows and biases,
/// their gaps and velocities left as they were (no touching point computed). For the
/// right-hand side of a hybrid run, where a separated contact adds no force and nothing reads
/// its gap (issue 24 item 2: a candidate that does not touch costs nothing per evaluation;
/// its event function and the recorded outputs compute its gap themselves,
/// [`contact_gaps_where`]).
pub fn contact_rows_only(model: &Model, data: &Data, contacts: &[Contact], rows: &mut ContactRows, rows_of: impl Fn(usize) -> bool) {
    fill_rows(model, data, contacts, rows, rows_of, false);
}

/// The gaps and velocities (`g`, `ġ`, `v_t`) of the contacts `which(k)`, by the operations of
/// [`contact_rows_where`] (the same values bit for bit); rows and biases left as they are.
pub fn contact_gaps_where(data: &Data, contacts: &[Contact], rows: &mut ContactRows, which: impl Fn(usize) -> bool) {
    for (k, c) in contacts.iter().enumerate() {
        if !which(k) {
            continue;
        }
        let n = c.plane.normal_world.into_inner();
        let touch = c.touch_moving(data);
        rows.gap[k] = touch.gap;
        for (axis, dir) in [n, c.t1, c.t2].iter().enumerate() {
            rows.vel[3 * k + axis] = dir.dot(&touch.velocity);
        }
    }
}

fn fill_rows(model: &Model, data: &Data, contacts: &[Contact], rows: &mut ContactRows, rows_of: impl Fn(usize) -> bool, others: bool) {
    let nv = model.nv;
    for (k, c) in contacts.iter().enumerate() {
        let full = rows_of(k);
        // the contact's three rows zero before they are filled (the Jacobian writes its
        // chain's columns only) or left empty: what a fill of the whole `jac` with zeros gave,
        // without writing the rows that are zero already
        if full || !rows.zero[k] {
            rows.jac[3 * k * nv..(3 * k + 3) * nv].fill(0.0);
        }
        rows.zero[k] = !full;
        if !full && !others {
            rows.bias[3 * k..3 * k + 3].fill(0.0);
            continue;
        }
        let n = c.plane.normal_world.into_inner();
        // J̇ q̇ only for the contacts with rows (the others' biases are 0)
        let touch = if full { c.touch(data) } else { c.touch_moving(data) };
        rows.gap[k] = touch.gap;
        for (axis, dir) in [n, c.t1, c.t2].iter().enumerate() {
            let r = 3 * k + axis;
            rows.vel[r] = dir.dot(&touch.velocity);
            if full {
                rows.bias[r] = dir.dot(&touch.bias);
                c.jacobian_along(model, data, &touch.point, dir, &mut rows.jac[r * nv..(r + 1) * nv]);
            } else {
                rows.bias[r] = 0.0;
            }
        }
    }
}

/// The q̇-dependent part of [`contact_rows_only`] (the same `rows_of`): the velocities
/// `ġ, v_t` and the biases `J̇ q̇` of the contacts `rows_of(k)`, from the kinematics in `data`
/// (at the same q as the rows, the q̇ given to `forward_velocities`); the gaps, `J` and the
/// other contacts are left as they are. The same operations as there, so the values are bit
/// for bit those of a full call.
pub fn contact_velocities_only(data: &Data, contacts: &[Contact], rows: &mut ContactRows, rows_of: impl Fn(usize) -> bool) {
    for (k, c) in contacts.iter().enumerate() {
        if !rows_of(k) {
            continue;
        }
        let n = c.plane.normal_world.into_inner();
        let touch = c.touch(data);
        for (axis, dir) in [n, c.t1, c.t2].iter().enumerate() {
            let r = 3 * k + axis;
            rows.vel[r] = dir.dot(&touch.velocity);
            rows.bias[r] = dir.dot(&touch.bias);
        }
    }
}

#[cfg(test)]
#[path = "rows_tests.rs"]
mod tests;
