//! Coulomb (with optional Stribeck) friction in the gear and a gear efficiency that depends on
//! the direction of the power flow, as a non-smooth law whose switches are events.
//!
//! Per joint j, at the link side of the gear (N m; N for a prismatic joint), with the motor's
//! electromagnetic torque reflected through an ideal gear `τ_em = K_m i` (eq 12):
//!
//! - **sliding** in direction `s = ±1` (q̇ s > 0), the gear delivers
//!   `τ_gear = c K_m i − τ_f(q̇) s` instead of `K_m i`, with the efficiency factor
//!   `c = η` while the motor drives the load (`K_m i s > 0`: power flows motor → load,
//!   `τ_out = η τ_in`) and `c = 1/η_b` while the load drives the motor (back-driving,
//!   `K_m i s < 0`: the load must supply `τ_in / η_b`), and the friction magnitude
//!   `τ_f(q̇) = τ_c + (τ_s − τ_c) exp(−(q̇/v_s)²)` (Stribeck; `τ_c` alone without a Stribeck
//!   speed). The loss `P_g = (K_m i − τ_gear) q̇ = (1 − c) K_m i q̇ + τ_f |q̇| ≥ 0` in the mode
//!   that matches the flow. Both factors give the same torque at `K_m i = 0`, so the change of
//!   power direction (a root of `K_m i s`) is continuous in τ; it is still an event so that each
//!   smooth phase has a smooth right-hand side (Armstrong-Hélouvry, Dupont & Canudas de Wit,
//!   *A survey of models, analysis tools and compensation methods for the control of machines
//!   with friction*, Automatica 30 (1994) 1083–1138, §2: Coulomb, static and Stribeck friction;
//!   the direction-dependent efficiency of a gear train: Pfeiffer, *Mechanical System Dynamics*,
//!   Springer 2008, §7.4 on gear losses, and the forward/backward efficiency curves of harmonic
//!   drives, Harmonic Drive AG, *Engineering Data CSD-2A*, "Efficiency");
//! - **sticking** (q̇ = 0 held, q̈ = 0): the gear supplies whatever torque λ keeps the joint at
//!   rest, as long as it lies in the static band. The joint would break away in the direction
//!   `s = −sign λ`; moving that way the gear would deliver `c_s K_m i − τ_s s`, so it holds while
//!   `|λ| ≤ τ_s + |1 − c_s| |K_m i|` ([`GearFriction::stick_margin`]): a gear of efficiency
//!   below 1 holds a part of the motor torque too (self-locking in the limit η_b → 0).
//!
//! **The stick band at rest** ([`GearFriction::band`]). At rest the law is set-valued: the
//! gear's torque is any value between the limits of the two sliding laws as q̇ → 0⁺ and q̇ → 0⁻
//! (the closure of the graph of a monotone friction law, Pfeiffer & Glocker 1996, ch. 5;
//! Glocker, *Set-Valued Force Laws*, Springer 2001, ch. 7), with T = K_m i:
//! `c₊ T − τ_s ≤ τ_gear ≤ c₋ T + τ_s`, `c₊` the factor of sliding + (η if T > 0, 1/η_b if T < 0)
//! and `c₋` of sliding − (1/η_b if T > 0, η if T < 0). In λ = τ_gear − T:
//!
//! ```text
//! T ≥ 0:  −τ_s − (1 − η) T      ≤ λ ≤ τ_s + (1/η_b − 1) T
//! T ≤ 0:  −τ_s − (1/η_b − 1) |T| ≤ λ ≤ τ_s + (1 − η) |T|
//! ```
//!
//! a band of width `2 τ_s + (1/η_b − η) |T|` that always holds λ = 0: a motor torque T alone
//! (no load) breaks away in its own direction, driving. For a load that needs the holding
//! torque W > 0 (λ = W − T), the joint is held for `η_b W ≤ T ≤ W / η` (τ_s = 0): above, the
//! motor lifts it (τ_out = η T, the forward efficiency); below, the load drives the motor
//! (τ_out = T / η_b, the backward one). This is the "stuck" mode of a gear with
//! load-dependent efficiency in Pelchen, Schweiger & Otter, *Modeling and simulating the
//! efficiency of gearboxes and of planetary gearboxes*, 2nd Modelica Conference 2002 (Modelica's
//! `LossyGear`: at rest the output torque lies between the forward and the backward law), in
//! our variables. [`GearFriction::stick_margin`] is the distance to the near edge,
//! `τ_s + |1 − c_s| |T| − |λ|` with `s = −sign λ`.
//!
//! At T = 0 and τ_s = 0 (an efficiency-only gear, no current) the band is the point λ = 0:
//! every load breaks away, and an unloaded joint has margin 0 whatever happens next. Which
//! mode holds there is decided by how the functions leave 0 (their slopes, then curvatures:
//! `ode/gear_decide.rs`); for that the edges are linear in T on each side of T = 0, with the
//! slopes [`GearFriction::band_slopes`] of the side T moves to.
//! The transitions are the events of Pfeiffer & Glocker, *Multibody Dynamics with Unilateral
//! Contacts* (Wiley 1996, ch. 5: stick–slip transitions as events of a hybrid system), handled in
//! `ode/drive_modes.rs`: slide → stick/reverse at a root of `s q̇`, stick → slide at a root of
//! the margin, driving ↔ back-driving at a root of `K_m i s`. The rotor inertia J_m is on the
//! motor side of the mesh but reflected without loss (its inertia torque passes the gear ideal,
//! as in the simple gear-with-loss models, e.g. Modelica `LossyGear`, Pelchen, Schweiger & Otter
//! 2002, which take the efficiency on the transmitted torque): the efficiency multiplies the
//! electromagnetic torque only, so the mass matrix stays symmetric and mode-independent.

/// The gear friction of every joint (link side), validated ([`crate::scene`]). Joints without
/// friction have τ_c = τ_s = 0 and η = η_b = 1.
#[derive(Clone, Debug, PartialEq)]
pub struct GearFriction {
    /// τ_c: Coulomb (sliding) friction torque, N m.
    pub coulomb: Vec<f64>,
    /// τ_s ≥ τ_c: the static (breakaway) torque, N m.
    pub breakaway: Vec<f64>,
    /// v_s: Stribeck speed, rad/s (0: no Stribeck term, τ_f = τ_c while sliding).
    pub stribeck_velocity: Vec<f64>,
    /// η: forward efficiency (motor drives the load), 0 < η ≤ 1.
    pub efficiency: Vec<f64>,
    /// η_b: backward efficiency (the load drives the motor), 0 < η_b ≤ 1.
    pub back_efficiency: Vec<f64>,
}

/// The discrete state of one joint's gear.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GearMode {
    /// q̇ = 0 held by the static friction.
    Stick,
    /// Moving in direction `dir` (±1); `driving`: power flows motor → load (`K_m i dir ≥ 0`).
    Slide { dir: i8, driving: bool },
}

impl GearMode {
    /// The sliding mode in direction `dir` with the power direction of `km_i` (a zero torque
    /// counts as driving: both factors agree there).
    pub fn slide(dir: f64, km_i: f64) -> Self {
        let dir: i8 = if dir < 0.0 { -1 } else { 1 };
        GearMode::Slide { dir, driving: km_i * f64::from(dir) >= 0.0 }
    }
}

impl GearFriction {
    pub fn nv(&self) -> usize {
        self.coulomb.len()
    }

    /// τ_f at speed `qd` while sliding, N m.
    #[inline]
    pub fn sliding_friction(&self, j: usize, qd: f64) -> f64 {
        let (tc, ts, vs) = (self.coulomb[j], self.breakaway[j], self.stribeck_velocity[j]);
        if vs > 0.0 && ts != tc {
            let x = qd / vs;
            tc + (ts - tc) * (-x * x).exp()
        } else {
            tc
        }
    }

    /// ∂τ_f/∂q̇ at `qd` (for the Jacobian), N m s/rad.
    #[inline]
    pub fn sliding_friction_slope(&self, j: usize, qd: f64) -> f64 {
        let (tc, ts, vs) = (self.coulomb[j], self.breakaway[j], self.stribeck_velocity[j]);
        if vs > 0.0 && ts != tc {
            let x = qd / vs;
            -2.0 * x / vs * (ts - tc) * (-x * x).exp()
        } else {
            0.0
        }
    }

    /// The efficiency factor c: η driving, 1/η_b back-driving.
    #[inline]
    pub fn factor(&self, j: usize, driving: bool) -> f64 {
        if driving {
            self.efficiency[j]
        } else {
            1.0 / self.back_efficiency[j]
        }
    }

    /// The gear's torque beyond the ideal train `K_m i` while sliding:
    /// `(c − 1) K_m i − τ_f(q̇) s`, N m (0 while sticking: λ is found by the solve).
    #[inline]
    pub fn sliding_torque(&self, j: usize, mode: GearMode, km_i: f64, qd: f64) -> f64 {
        match mode {
            GearMode::Stick => 0.0,
            GearMode::Slide { dir, driving } => (self.factor(j, driving) - 1.0) * km_i - self.sliding_friction(j, qd) * f64::from(dir),
        }
    }

    /// How far the holding torque λ of a sticking joint is inside the static band:
    /// `τ_s + |1 − c_s| |K_m i| − |λ|` with `s = −sign λ` (module docs); < 0: it breaks away.
    #[inline]
    pub fn stick_margin(&self, j: usize, km_i: f64, lambda: f64) -> f64 {
        let dir = if lambda > 0.0 { -1.0 } else { 1.0 };
        let driving = km_i * dir >= 0.0;
        self.breakaway[j] + (1.0 - self.factor(j, driving)).abs() * km_i.abs() - lambda.abs()
    }

    /// The stick band at rest (module docs): λ, the gear's torque beyond the ideal train,
    /// holds the joint while `lo ≤ λ ≤ hi`, N m.
    #[inline]
    pub fn band(&self, j: usize, km_i: f64) -> (f64, f64) {
        let ts = self.breakaway[j];
        // sliding + is driving for T > 0; sliding − for T < 0 (both factors agree at T = 0)
        let (c_plus, c_minus) = if km_i >= 0.0 { (self.efficiency[j], 1.0 / self.back_efficiency[j]) } else { (1.0 / self.back_efficiency[j], self.efficiency[j]) };
        ((c_plus - 1.0) * km_i - ts, (c_minus - 1.0) * km_i + ts)
    }

    /// dlo/dT and dhi/dT of [`GearFriction::band`] on the side `side` (> 0: T > 0, < 0:
    /// T < 0) of T = 0, where the band's edges are linear in T.
    #[inline]
    pub fn band_slopes(&self, j: usize, side: f64) -> (f64, f64) {
        if side >= 0.0 {
            (self.efficiency[j] - 1.0, 1.0 / self.back_efficiency[j] - 1.0)
        } else {
            (1.0 / self.back_efficiency[j] - 1.0, self.efficiency[j] - 1.0)
        }
    }

    /// Whether joint j has any gear law (else its events are constants).
    pub fn active(&self, j: usize) -> bool {
        self.breakaway[j] > 0.0 || self.efficiency[j] != 1.0 || self.back_efficiency[j] != 1.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn one(tc: f64, ts: f64, vs: f64, eta: f64, eta_b: f64) -> GearFriction {
        GearFriction { coulomb: vec![tc], breakaway: vec![ts], stribeck_velocity: vec![vs], efficiency: vec![eta], back_efficiency: vec![eta_b] }
    }

    /// The loss `(K_m i − τ_gear) q̇` is ≥ 0 in the mode that matches the power flow, and equals
    /// `(1 − η) K_m i q̇ + τ_c |q̇|` (driving), `(1/η_b − 1) |K_m i q̇| + τ_c |q̇|` (back-driving).
    #[test]
    fn the_loss_is_non_negative_and_as_stated() {
        let g = one(0.3, 0.3, 0.0, 0.8, 0.6);
        for &(km_i, qd) in &[(2.0, 1.5), (-2.0, 1.5), (2.0, -0.5), (-1.0, -3.0)] {
            let mode = GearMode::slide(qd, km_i);
            let tau = km_i + g.sliding_torque(0, mode, km_i, qd);
            let loss = (km_i - tau) * qd;
            let expect = if km_i * qd > 0.0 { 0.2 * km_i * qd } else { (1.0 / 0.6 - 1.0) * (km_i * qd).abs() } + 0.3 * qd.abs();
            assert!(loss >= 0.0 && (loss - expect).abs() < 1e-14, "{km_i} {qd}: {loss} vs {expect}");
        }
    }

    /// Stribeck: τ_f(0) = τ_s, τ_f(∞) = τ_c, and the slope is the derivative (central differences).
    #[test]
    fn stribeck_curve_and_slope() {
        let g = one(0.2, 0.5, 0.1, 1.0, 1.0);
        assert_eq!(g.sliding_friction(0, 0.0), 0.5);
        assert!((g.sliding_friction(0, 10.0) - 0.2).abs() < 1e-15);
        for &v in &[0.03, 0.1, -0.2] {
            let h = 1e-6;
            let fd = (g.sliding_friction(0, v + h) - g.sliding_friction(0, v - h)) / (2.0 * h);
            assert!((fd - g.sliding_friction_slope(0, v)).abs() < 1e-7, "{v}");
        }
    }

    /// The static band: a holding torque up to τ_s + |1 − c| |K_m i| holds.
    #[test]
    fn the_static_band_includes_the_efficiency() {
        let g = one(0.1, 0.2, 0.0, 0.5, 0.5);
        // K_m i = 1: breaking away against λ < 0 means moving +: driving, c = 0.5 → band 0.7
        assert!((g.stick_margin(0, 1.0, -0.7)).abs() < 1e-15);
        // breaking away with λ > 0 means moving −: back-driving, c = 2 → band 1.2
        assert!((g.stick_margin(0, 1.0, 1.2)).abs() < 1e-15);
    }

    /// The band is the interval between the sliding laws' limits at q̇ → 0±, `c₊ T − τ_s` and
    /// `c₋ T + τ_s` less T, on both sides of T = 0; its edges are the stick margin's zeros;
    /// the slopes are the edges' difference quotients on each side; a load W is held for
    /// `η_b W ≤ T ≤ W / η`.
    #[test]
    fn the_band_is_between_the_sliding_limits_and_holds_a_load_between_the_efficiencies() {
        let (eta, eta_b) = (0.8, 0.6);
        for ts in [0.0, 0.1] {
            let g = one(ts, ts, 0.0, eta, eta_b);
            for t in [-2.0, -0.5, 0.0, 0.5, 2.0] {
                let (lo, hi) = g.band(0, t);
                let plus = t + g.sliding_torque(0, GearMode::slide(1.0, t), t, 1e-3);
                let minus = t + g.sliding_torque(0, GearMode::slide(-1.0, t), t, -1e-3);
                assert!((lo - (plus - t)).abs() < 1e-15 && (hi - (minus - t)).abs() < 1e-15, "T = {t}: [{lo}, {hi}] vs [{}, {}]", plus - t, minus - t);
                assert!(lo <= -ts && hi >= ts);
                assert!((hi - lo - (2.0 * ts + (1.0 / eta_b - eta) * t.abs())).abs() < 1e-15, "width at T = {t}");
                if lo < 0.0 {
                    assert!(g.stick_margin(0, t, lo).abs() < 1e-15, "T = {t}: margin at lo");
                }
                if hi > 0.0 {
                    assert!(g.stick_margin(0, t, hi).abs() < 1e-15, "T = {t}: margin at hi");
                }
            }
            for side in [-1.0, 1.0] {
                let (klo, khi) = g.band_slopes(0, side);
                let (lo1, hi1) = g.band(0, side);
                let (lo2, hi2) = g.band(0, 2.0 * side);
                assert!(((lo2 - lo1) / side - klo).abs() < 1e-15 && ((hi2 - hi1) / side - khi).abs() < 1e-15, "side {side}");
            }
        }
        // a load needing W = 3 N m: λ = W − T in the band exactly for T in [η_b W, W / η]
        let g = one(0.0, 0.0, 0.0, eta, eta_b);
        let w = 3.0;
        let held = |t: f64| {
            let (lo, hi) = g.band(0, t);
            (lo - 1e-12..=hi + 1e-12).contains(&(w - t))
        };
        assert!(held(eta_b * w) && held(w / eta) && held(w));
        assert!(!held(eta_b * w * (1.0 - 1e-9)) && !held(w / eta * (1.0 + 1e-9)) && !held(0.0));
    }
}
