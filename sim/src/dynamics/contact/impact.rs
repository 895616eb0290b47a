//! Impacts: the velocity-level complementarity problem of Newton's restitution in the form of
//! Pfeiffer & Glocker (1996, §6.2; Glocker's "Newton's law" with the impenetrability
//! inequality, also Acary & Brogliato 2008, §3.2): for the unilateral contacts `I` at the
//! table (|g| ≤ gap_tol) and the bilateral ones `B`,
//!
//! ```text
//! ġ⁺ = ġ⁻ + W M_J⁻¹ Wᵀ Λ,   Λ_I ≥ 0,  ġ⁺_I + e ġ⁻_I ≥ 0,  Λ_I ⟂ (ġ⁺_I + e ġ⁻_I),   ġ⁺_B = 0
//! ```
//!
//! (W the normal rows; M_J = M + J_m, the rotors take part in the impact), solved by exact
//! enumeration of the set of contacts with a positive impulse (2^m, m ≤ 8). FRICTIONLESS
//! impulses: no tangential impulse (Newton's law with Coulomb friction in the impulse can
//! create energy, Kane & Levinson 1985); friction acts in the contact phases. The velocity jump
//! is `Δq̇ = M_J⁻¹ Wᵀ Λ`, the kinetic energy lost `½ q̇⁻ᵀ M_J q̇⁻ − ½ q̇⁺ᵀ M_J q̇⁺ =
//! Σ_k −Λ_k (ġ⁻_k + ġ⁺_k)/2`, split among the contacts by that sum.

use super::rows::ContactRows;
use super::solve::{solve_active, ActiveRow, ActiveScratch, RowForce};
use super::{Contact, MAX_CLOSED_CONTACTS};
use crate::error::DynamicsError;

/// The result of an impact: per contact of the run (0 for those not involved).
#[derive(Clone, Debug, PartialEq)]
pub struct Impact {
    /// Normal impulse Λ, N s.
    pub impulse: Vec<f64>,
    /// Gap rates before and after, m/s.
    pub gap_rate_before: Vec<f64>,
    pub gap_rate_after: Vec<f64>,
    /// Kinetic energy lost at each contact, J (sums to the total loss).
    pub energy_lost: Vec<f64>,
    /// The velocity jump Δq̇ (nv), rad/s.
    pub dqd: Vec<f64>,
}

/// Solve the impact at a state whose rows are in `rows` and whose `M_J` is factored (`l`,
/// `inv`): `unilateral` are the contacts at the table with their restitution (already 0 for
/// the Zeno rule), `bilateral` the bilateral ones.
#[allow(clippy::too_many_arguments)]
pub fn solve_impact(
    contacts: &[Contact],
    rows: &ContactRows,
    l: &[f64],
    inv: &[f64],
    unilateral: &[(usize, f64)],
    bilateral: &[usize],
    t: f64,
) -> Result<Impact, DynamicsError> {
    let nv = rows.nv;
    let nc = contacts.len();
    let m = unilateral.len();
    let names = || unilateral.iter().map(|&(k, _)| contacts[k].name()).collect::<Vec<_>>().join(", ");
    if m > MAX_CLOSED_CONTACTS {
        return Err(DynamicsError::InconsistentContact { t, contact: names(), why: format!("an impact with more than {MAX_CLOSED_CONTACTS} rigid contacts at the table: use compliant contacts") });
    }
    let zeros = vec![0.0; nv];
    let mut scratch = ActiveScratch::new(nv, nc);
    let mut dqd = vec![0.0; nv];
    let gd = |k: usize| rows.vel[3 * k];
    let vmax = unilateral.iter().fold(0.0f64, |a, &(k, _)| a.max(gd(k).abs()));
    let tol = 1e-9 * (1.0 + vmax);
    for set in 0u32..(1u32 << m) {
        let mut active = Vec::new();
        // solve_active's right-hand side is −bias − extra − W M⁻¹ b with b = 0: extra = ġ⁻ − target − bias
        for (i, &(k, e)) in unilateral.iter().enumerate() {
            if set & (1 << i) != 0 {
                active.push(ActiveRow { row: 3 * k, force: RowForce::Same, extra: gd(k) + e * gd(k) - rows.bias[3 * k] });
            }
        }
        for &k in bilateral {
            active.push(ActiveRow { row: 3 * k, force: RowForce::Same, extra: gd(k) - rows.bias[3 * k] });
        }
        if active.is_empty() {
            dqd.fill(0.0);
        } else if solve_active(l, inv, &zeros, rows, &active, &mut scratch, &mut dqd).is_err() {
            continue;
        }
        let mut ok = true;
        let mut impulse = vec![0.0; nc];
        for (i, a) in active.iter().enumerate() {
            impulse[a.row / 3] = scratch.lambda[i];
        }
        let imax = impulse.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        let after = |k: usize| gd(k) + rows.dot(3 * k, &dqd);
        for (i, &(k, e)) in unilateral.iter().enumerate() {
            if set & (1 << i) != 0 {
                ok &= impulse[k] >= -1e-9 * (1.0 + imax);
            } else {
                ok &= after(k) + e * gd(k) >= -tol;
            }
        }
        if !ok {
            continue;
        }
        let mut before = vec![0.0; nc];
        let mut aft = vec![0.0; nc];
        let mut lost = vec![0.0; nc];
        for k in unilateral.iter().map(|&(k, _)| k).chain(bilateral.iter().copied()) {
            before[k] = gd(k);
            aft[k] = after(k);
            lost[k] = -impulse[k] * (before[k] + aft[k]) / 2.0;
        }
        return Ok(Impact { impulse, gap_rate_before: before, gap_rate_after: aft, energy_lost: lost, dqd });
    }
    Err(DynamicsError::InconsistentContact { t, contact: names(), why: impact_failure(contacts, bilateral) })
}

/// Why the impact problem over the unilateral contacts (named in the error's `contact`) and
/// `bilateral` has no solution: every active set gave a singular or infeasible system (review F6).
fn impact_failure(contacts: &[Contact], bilateral: &[usize]) -> String {
    let mut why = String::from("the impact problem (Newton's law over the unilateral contacts at the table");
    if !bilateral.is_empty() {
        let names: Vec<&str> = bilateral.iter().map(|&k| contacts[k].name()).collect();
        why.push_str(&format!(", with the bilateral contacts {} as equalities", names.join(", ")));
    }
    why.push_str(") has no solution: every active set is singular or infeasible (redundant contacts?)");
    why
}
