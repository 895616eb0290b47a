//! Slip→stick of sliding contacts at the located zero of their slip (`hybrid.rs`, `stops_here`:
//! `|v_t| ≤ vel_tol` there): an M_J-weighted velocity projection of the slip left at the root
//! (≤ 1e-9 m/s; Pfeiffer & Glocker 1996, ch. 6: the impulsive limit of Coulomb friction;
//! Acary & Brogliato 2008, ch. 7), its kinetic-energy loss booked per contact as friction work.
//! The same projection removes a breaking stick's drift (~1e-13 m/s) at a stick → slip onset,
//! so the slide starts from rest exactly. Split from `hybrid.rs` (file size).

use crate::dynamics::contact::ContactMode;
use crate::error::{DynamicsError, RunError};

use super::arm::ArmSystem;

impl ArmSystem<'_> {
    /// Slip→stick at the slip's zero (`|v_t| ≤ vel_tol`): the remaining slip velocity of the `stopping`
    /// contacts is removed by the M_J-weighted velocity projection that keeps the other active
    /// velocity rows (normal rows of the contacts in touch, tangential rows of the sticking
    /// ones) — the impulse friction would deliver over the root's bracket — and its kinetic
    /// energy loss (≤ ½ m vel_tol²) is booked as friction work (the rotors' share of the
    /// jump into W_j, as at impacts), so the balance stays closed.
    pub(super) fn stop_slip(&mut self, t: f64, y: &mut [f64], stopping: &[usize]) -> Result<(), RunError> {
        use crate::dynamics::contact::solve::{solve_active, ActiveRow, RowForce};
        let l = self.layout;
        let nv = l.nv;
        self.prepare_at(t, y)?;
        let h = self.hybrid.as_mut().expect("hybrid");
        let r = &h.cd.rows;
        let mut rows = Vec::new();
        for k in 0..h.contacts.len() {
            let m = h.state.mode[k];
            if matches!(m, ContactMode::Sticking | ContactMode::Sliding | ContactMode::Bilateral) {
                rows.push(ActiveRow { row: 3 * k, force: RowForce::Same, extra: r.vel[3 * k] - r.bias[3 * k] });
            }
            if m == ContactMode::Sticking || stopping.contains(&k) {
                for a in 1..3 {
                    rows.push(ActiveRow { row: 3 * k + a, force: RowForce::Same, extra: r.vel[3 * k + a] - r.bias[3 * k + a] });
                }
            }
        }
        let zeros = vec![0.0; nv];
        let mut dqd = vec![0.0; nv];
        let fd = &self.ws.fd;
        if solve_active(fd.m_j.as_slice(), &fd.l_inv_diag, &zeros, r, &rows, &mut h.cd.scratch, &mut dqd).is_err() {
            // name the contacts whose rows are involved (review F6)
            let mut names: Vec<&str> = Vec::new();
            for a in &rows {
                let n = h.contacts[a.row / 3].name();
                if !names.contains(&n) {
                    names.push(n);
                }
            }
            let stop: Vec<&str> = stopping.iter().map(|&k| h.contacts[k].name()).collect();
            return Err(DynamicsError::SingularConstraints {
                t,
                constraints: format!("the slip-to-stick velocity projection stopping {} (rows of {})", stop.join(", "), names.join(", ")),
            }
            .into());
        }
        // per-contact loss ΔT_k = −Λ_kᵀ(v⁻_k + v⁺_k)/2 over the contact's rows (as impact.rs;
        // the terms sum to ΔT), Λ in `rows` order (review F7)
        let mut lost_k = vec![0.0; h.contacts.len()];
        for (i, a) in rows.iter().enumerate() {
            let v_before = r.vel[a.row];
            let v_after = v_before + r.dot(a.row, &dqd);
            lost_k[a.row / 3] -= h.cd.scratch.lambda[i] * (v_before + v_after) / 2.0;
        }
        // ΔT = −(q̇⁻ + ½ Δq̇)ᵀ M_J Δq̇ with M_J = M + J_m (data.m from this evaluation)
        let d = &self.scene.drives;
        let m = &self.ws.data.m;
        let mut lost = 0.0;
        for i in 0..nv {
            let mut md = d.jm[i] * dqd[i];
            for j in 0..nv {
                md += m[(i, j)] * dqd[j];
            }
            lost -= (y[l.qd().start + i] + 0.5 * dqd[i]) * md;
        }
        for j in 0..nv {
            let before = y[l.qd().start + j];
            let after = before + dqd[j];
            y[l.work().start + j] += -d.jm[j] * (after * after - before * before) / 2.0;
            y[l.qd().start + j] = after;
        }
        // the normal-row terms of contacts that do not stop are drift corrections, booked to
        // their own contact; the split sums to ΔT up to the solve's rounding, which goes to the
        // first stopping contact so the booked total is exactly the kinetic-energy loss
        let rounding = lost - lost_k.iter().sum::<f64>();
        lost_k[stopping[0]] += rounding;
        for (k, x) in lost_k.iter().enumerate() {
            y[l.friction_work(k)] += x;
        }
        Ok(())
    }
}
