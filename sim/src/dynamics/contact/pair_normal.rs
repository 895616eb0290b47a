//! The normal problem of two closed sliding contacts (issue 23 item 6, the see-saw of two
//! landings): with contact i sliding along `s_i` its friction is `−μ_i f_n,i s_i`, so the
//! normal accelerations of the pair are `g̈ = a0 + A f_n` with
//!
//! ```text
//! A_ij = G_nn,ij − μ_j G_nt,ij · s_j
//! ```
//!
//! (G the pair's Delassus matrix `J M_J⁻¹ Jᵀ` with the other contacts in their modes, m s⁻² N⁻¹;
//! Pfeiffer & Glocker 1996, §5.2, the acceleration-level problem of the sliding contacts; its
//! one-contact case is `p(s) = G_nn − μ G_nt·s`, `modes::OneContact`), and Coulomb's law at the
//! pair is the LCP `g̈ = a0 + A f_n ≥ 0, f_n ≥ 0, f_n ⟂ g̈` (Glocker 2001; Brogliato 2016, §5.5).
//! A is not symmetric and need not be a P-matrix: with positive diagonal (each contact alone
//! consistent) and both single-closed modes infeasible (each contact, the other closed and
//! sliding, accelerating into the table: `w_i = a0_i − A_ij a0_j / A_jj < 0`) both closed has
//! `f_n,i = −A_jj w_i / det A` (Cramer), positive iff `det A > 0`; with `det A ≤ 0` the LCP has
//! no solution (Painlevé's inconsistency of the pair; Génot & Brogliato 1999 for one contact).
//! Computed column by column from unit forces `n_j − μ_j s_j` on contact j's rows (the
//! equations are linear), as `modes::one_contact` does. Events and diagnostics only (allocates).

use super::forward::{solve_modes, ContactData, ContactState};
use super::{Contact, ContactMode};
use crate::dynamics::forward::{ForwardData, Stabilization};

/// The pair's normal problem at a state (m s⁻² N⁻¹ and m/s²).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PairNormal {
    /// `A_ij = G_nn,ij − μ_j G_nt,ij · s_j`.
    pub a: [[f64; 2]; 2],
    /// `G_nn,ij`, the frictionless part of `A`.
    pub g_nn: [[f64; 2]; 2],
    /// The pair's normal accelerations with neither pressed (`a0`).
    pub a0: [f64; 2],
    /// The frictions μ_j.
    pub mu: [f64; 2],
}

impl PairNormal {
    pub fn det(&self) -> f64 {
        self.a[0][0] * self.a[1][1] - self.a[0][1] * self.a[1][0]
    }

    /// Both closed: `f_n = A⁻¹ (−a0)` (N; NaN when `det A = 0`).
    pub fn both_closed(&self) -> [f64; 2] {
        let d = self.det();
        let (r0, r1) = (-self.a0[0], -self.a0[1]);
        [(self.a[1][1] * r0 - self.a[0][1] * r1) / d, (self.a[0][0] * r1 - self.a[1][0] * r0) / d]
    }

    /// Contact i's normal acceleration with only the other (j) closed, sliding:
    /// `w_i = a0_i − A_ij a0_j / A_jj` (m/s²).
    pub fn other_closed(&self, i: usize) -> f64 {
        let j = 1 - i;
        self.a0[i] - self.a[i][j] * self.a0[j] / self.a[j][j]
    }

    /// The largest factor λ ∈ (0, 1] on both frictions (μ_j → λ μ_j) up to which `det A > 0`
    /// holds from λ = 0 (where it is `det G_nn > 0`): the smallest positive root of the
    /// quadratic `det(G_nn − λ B)`, B = G_nn − A; None when there is none below 1.
    pub fn friction_factor(&self) -> Option<f64> {
        let (g, a) = (self.g_nn, self.a);
        let b = |i: usize, j: usize| g[i][j] - a[i][j];
        // det(G − λB) = c0 + c1 λ + c2 λ²
        let c0 = g[0][0] * g[1][1] - g[0][1] * g[1][0];
        let c1 = -(g[0][0] * b(1, 1) + b(0, 0) * g[1][1]) + (g[0][1] * b(1, 0) + b(0, 1) * g[1][0]);
        let c2 = b(0, 0) * b(1, 1) - b(0, 1) * b(1, 0);
        let roots: Vec<f64> = if c2.abs() <= 1e-14 * (c1.abs() + c0.abs()) {
            vec![-c0 / c1]
        } else {
            let disc = c1 * c1 - 4.0 * c2 * c0;
            if disc < 0.0 {
                vec![]
            } else {
                vec![(-c1 - disc.sqrt()) / (2.0 * c2), (-c1 + disc.sqrt()) / (2.0 * c2)]
            }
        };
        roots.into_iter().filter(|&l| l.is_finite() && l > 0.0 && l <= 1.0).reduce(f64::min)
    }
}


/// [`PairNormal`] of contacts `ks` sliding along `s` (unit, tangent basis), the other contacts
/// in `state`'s modes, after [`super::forward::prepare`] at the state; None when a solve is
/// singular. Leaves `fd.b` as it found it.
pub fn pair_normal(contacts: &[Contact], state: &ContactState, ks: [usize; 2], s: [[f64; 2]; 2], stabilization: Stabilization, fd: &mut ForwardData, cd: &mut ContactData) -> Option<PairNormal> {
    let nv = cd.rows.nv;
    let mut st = state.clone();
    for &k in &ks {
        st.mode[k] = ContactMode::Separated;
        st.onset[k] = None;
    }
    let b0 = fd.b.clone();
    let normal = |fd: &ForwardData, cd: &ContactData| -> [f64; 2] {
        let qdd = &fd.qdd.as_slice()[..nv];
        std::array::from_fn(|i| cd.rows.dot(3 * ks[i], qdd) + cd.rows.bias[3 * ks[i]])
    };
    let mu = [contacts[ks[0]].unilateral_friction(), contacts[ks[1]].unilateral_friction()];
    let mut out = None;
    if solve_modes(contacts, &st, stabilization, fd, cd).is_ok() {
        let a0 = normal(fd, cd);
        let mut a = [[0.0; 2]; 2];
        let mut g_nn = [[0.0; 2]; 2];
        let mut ok = true;
        for j in 0..2 {
            for (with_friction, m) in [(false, &mut g_nn), (true, &mut a)] {
                fd.b.copy_from(&b0);
                let k = ks[j];
                let f = if with_friction { mu[j] } else { 0.0 };
                let (rn, r1, r2) = (cd.rows.row(3 * k), cd.rows.row(3 * k + 1), cd.rows.row(3 * k + 2));
                for (v, bj) in fd.b.iter_mut().enumerate() {
                    *bj += rn[v] - f * (s[j][0] * r1[v] + s[j][1] * r2[v]);
                }
                ok &= solve_modes(contacts, &st, stabilization, fd, cd).is_ok();
                let a1 = normal(fd, cd);
                for i in 0..2 {
                    m[i][j] = a1[i] - a0[i];
                }
            }
        }
        if ok {
            out = Some(PairNormal { a, g_nn, a0, mu });
        }
    }
    fd.b.copy_from(&b0);
    out
}

/// The pairs of closed frictional contacts, both sliding (`|v_t| > vel_tol`, along `v_t`), whose
/// normal problem has `det A ≤ 0` (no solution with both closed): the error's part for each
/// (the mode problem found no consistent combination; `modes::choose_modes`). For events only.
#[allow(clippy::too_many_arguments)]
pub fn painleve_pairs(contacts: &[Contact], state: &ContactState, closed: &[usize], vel_tol: f64, stabilization: Stabilization, fd: &mut ForwardData, cd: &mut ContactData) -> Vec<String> {
    let sliding: Vec<(usize, [f64; 2])> = closed
        .iter()
        .filter(|&&k| contacts[k].unilateral_friction() > 0.0)
        .filter_map(|&k| {
            let v = cd.rows.slip(k);
            let m = v[0].hypot(v[1]);
            (m > vel_tol).then(|| (k, [v[0] / m, v[1] / m]))
        })
        .collect();
    let mut out = Vec::new();
    for (i, &(k1, s1)) in sliding.iter().enumerate() {
        for &(k2, s2) in &sliding[i + 1..] {
            let mut st = state.clone();
            for &k in &[k1, k2] {
                st.mode[k] = ContactMode::Sliding;
            }
            let Some(p) = pair_normal(contacts, &st, [k1, k2], [s1, s2], stabilization, fd, cd) else { continue };
            if p.det() > 0.0 {
                continue;
            }
            let f = p.both_closed();
            let change = match p.friction_factor() {
                Some(l) => format!("frictions below {l:.4} of theirs ({:.4}, {:.4}) make det A > 0", l * p.mu[0], l * p.mu[1]),
                None => String::from("no smaller common friction factor makes det A > 0"),
            };
            out.push(format!(
                "{} and {} sliding together: their normal problem A f_n = -a_n has A = [[{:.6e}, {:.6e}], [{:.6e}, {:.6e}]] m/(s^2 N) (A_ij = G_nn,ij - mu_j G_nt,ij.s_j), det A = {:.6e} <= 0 (det G_nn = {:.6e}) and a_n = ({:.6e}, {:.6e}) m/s^2, so both closed would need f_n = ({:.6e}, {:.6e}) N and each, the other closed, accelerates {} and {} m/s^2: Coulomb's law has no solution with both closed (Painleve's inconsistency of the pair); {change}, or use compliant contacts",
                contacts[k1].name(),
                contacts[k2].name(),
                p.a[0][0],
                p.a[0][1],
                p.a[1][0],
                p.a[1][1],
                p.det(),
                p.g_nn[0][0] * p.g_nn[1][1] - p.g_nn[0][1] * p.g_nn[1][0],
                p.a0[0],
                p.a0[1],
                f[0],
                f[1],
                fmt_accel(p.other_closed(0)),
                fmt_accel(p.other_closed(1)),
            ));
        }
    }
    out
}

fn fmt_accel(w: f64) -> String {
    format!("{} ({w:.6e}", if w < 0.0 { "into the table" } else { "away" }) + ")"
}

#[cfg(test)]
mod tests {
    use super::PairNormal;

    /// The pair's arithmetic against a hand solution: A = [[2, 1], [3, 1]] (det −1), a0 = (−1, −1):
    /// both closed by Cramer f = A⁻¹(1, 1) = (0, 1); w_0 = −1 − 1·(−1)/1 = 0, w_1 = −1 − 3·(−1)/2 = 1/2;
    /// with G_nn = [[2, 0], [0, 2]] (B = G − A = [[0, −1], [−3, 1]]) det(G − λB) = (2)(2 − λ) − (λ)(3λ)
    /// = 4 − 2λ − 3λ², whose positive root is (−2 + √52)/6 = 0.868517…
    #[test]
    fn the_pair_problem_against_a_hand_solution() {
        let p = PairNormal { a: [[2.0, 1.0], [3.0, 1.0]], g_nn: [[2.0, 0.0], [0.0, 2.0]], a0: [-1.0, -1.0], mu: [1.0, 1.0] };
        assert_eq!(p.det(), -1.0);
        assert_eq!(p.both_closed(), [0.0, 1.0]);
        assert_eq!((p.other_closed(0), p.other_closed(1)), (0.0, 0.5));
        let l = p.friction_factor().unwrap();
        assert!((l - (-2.0 + 52f64.sqrt()) / 6.0).abs() < 1e-15, "{l}");
        let ok = PairNormal { a: [[2.0, 0.5], [0.5, 2.0]], g_nn: [[2.0, 0.5], [0.5, 2.0]], a0: [-1.0, -1.0], mu: [0.0, 0.0] };
        assert!(ok.det() > 0.0 && ok.friction_factor().is_none());
    }
}
