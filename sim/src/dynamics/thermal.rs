//! The winding temperature of each motor: a two-node lumped thermal network (winding and
//! housing), heated by the copper loss `R(T_w) i²`, with the winding resistance rising with its
//! temperature.
//!
//! Per motor (temperatures in °C; only differences enter, so °C and K are interchangeable):
//!
//! ```text
//! C_w dT_w/dt = R(T_w) i² − (T_w − T_h) / R_th1
//! C_h dT_h/dt = (T_w − T_h) / R_th1 − (T_h − T_a) / R_th2
//! ```
//!
//! with R_th1 the thermal resistance winding–housing, R_th2 housing–ambient (K/W), and the heat
//! capacities from the catalogue's thermal time constants, `C_w = τ_w / R_th1` and
//! `C_h = τ_h / R_th2` (J/K): maxon's convention ("Key information", *maxon DC motor and maxon
//! EC motor*, May 2009 edition, p. 36 ff., "Thermal behaviour": the winding's time constant τ_w
//! is that of the winding against the housing, the motor's τ_s that of the housing against the
//! ambient; the datasheets' lines 17–20 give R_th2, R_th1, τ_w, τ_s). The
//! network is the standard lumped-parameter model of small machines (Mellor, Roberts & Turner,
//! "Lumped parameter thermal model for electrical machines of TEFC design", IEE Proc. B 138(5),
//! 1991), cut to the two nodes a datasheet gives.
//!
//! The resistance of copper is linear in temperature, `R(T) = R_20 (1 + α_20 (T − 20 °C))`
//! with `α_20 = 0.00393 /K` (IEC 60028:1925, *International standard of resistance for copper*:
//! annealed copper, 20 °C). A datasheet gives the terminal resistance at a reference
//! temperature T_ref (25 °C on maxon's sheets, 22 °C on Faulhaber's), so
//! `R(T) = R_ref (1 + α_20 (T − 20)) / (1 + α_20 (T_ref − 20))`: exact for the linear law
//! whatever T_ref, and equal to R_ref at T = T_ref.
//!
//! Heat in the energy balance: the electrical balance keeps its term `E_R = ∫ Σ R(T_w) i² dt`
//! (the electrical equation, eq 11, uses the same R(T_w), so it still closes); the thermal
//! network then books that heat as `E_R = Σ [C_w (T_w − T_0) + C_h (T_h − T_0)] + Q_a`, with
//! `Q_a = ∫ Σ (T_h − T_a) / R_th2 dt` the heat given to the ambient (a quadrature of the run).
//!
//! Brushes, iron and friction losses are not heat sources here (maxon's ironless windings have
//! no iron loss; the friction loss is booked in the mechanical terms); the model is that of a
//! datasheet: one winding node, one housing node, no conduction into the arm's structure.

/// The thermal data of one motor (a datasheet's "Thermal data" block), SI but temperatures in
/// °C.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThermalParams {
    /// R_th1: thermal resistance winding–housing, K/W.
    pub r_winding_housing: f64,
    /// R_th2: thermal resistance housing–ambient, K/W.
    pub r_housing_ambient: f64,
    /// τ_w: thermal time constant of the winding, s.
    pub tau_winding: f64,
    /// τ_s: thermal time constant of the motor (housing), s.
    pub tau_housing: f64,
    /// The winding's maximum temperature, °C (monitored, not enforced).
    pub max_winding_temperature: f64,
    /// T_ref: the temperature at which the terminal resistance is given, °C.
    pub reference_temperature: f64,
    /// α_20: the temperature coefficient of the winding's resistance at 20 °C, 1/K.
    pub alpha_20: f64,
}

/// The temperature coefficient of copper's resistance at 20 °C, 1/K (IEC 60028).
pub const ALPHA_COPPER_20: f64 = 0.00393;

impl ThermalParams {
    /// C_w = τ_w / R_th1, J/K.
    pub fn c_winding(&self) -> f64 {
        self.tau_winding / self.r_winding_housing
    }
    /// C_h = τ_s / R_th2, J/K.
    pub fn c_housing(&self) -> f64 {
        self.tau_housing / self.r_housing_ambient
    }
    /// `R(T) / R_ref` at the winding temperature `t_w`, °C.
    #[inline]
    pub fn resistance_factor(&self, t_w: f64) -> f64 {
        (1.0 + self.alpha_20 * (t_w - 20.0)) / (1.0 + self.alpha_20 * (self.reference_temperature - 20.0))
    }
    /// `d(R / R_ref) / dT`, 1/K.
    #[inline]
    pub fn resistance_slope(&self) -> f64 {
        self.alpha_20 / (1.0 + self.alpha_20 * (self.reference_temperature - 20.0))
    }
}

/// The thermal model of a scene's motors (read-only): present only when the scene turns it on.
/// Joints without thermal data (passive joints) keep their resistance and their temperatures.
#[derive(Clone, Debug, PartialEq)]
pub struct Thermal {
    /// Per joint: its motor's thermal data, or `None` (no heating, constant R).
    pub params: Vec<Option<ThermalParams>>,
    /// T_a, the ambient temperature, °C.
    pub ambient: f64,
    /// T_0, both nodes' temperature at t = 0, °C.
    pub initial: f64,
    /// R_ref per joint (the drive's terminal resistance at T_ref), ohm.
    pub r_ref: Vec<f64>,
}

impl Thermal {
    pub fn nv(&self) -> usize {
        self.params.len()
    }

    /// R(T_w) of joint j, ohm.
    #[inline]
    pub fn resistance(&self, j: usize, t_w: f64) -> f64 {
        match &self.params[j] {
            Some(p) => self.r_ref[j] * p.resistance_factor(t_w),
            None => self.r_ref[j],
        }
    }

    /// `dR/dT_w` of joint j, ohm/K.
    #[inline]
    pub fn resistance_slope(&self, j: usize) -> f64 {
        self.params[j].as_ref().map_or(0.0, |p| self.r_ref[j] * p.resistance_slope())
    }

    /// `(dT_w/dt, dT_h/dt)` of joint j for the copper loss `p_cu` (W) at `(t_w, t_h)`, K/s.
    #[inline]
    pub fn rates(&self, j: usize, p_cu: f64, t_w: f64, t_h: f64) -> (f64, f64) {
        match &self.params[j] {
            Some(p) => {
                let q_wh = (t_w - t_h) / p.r_winding_housing;
                let q_ha = (t_h - self.ambient) / p.r_housing_ambient;
                ((p_cu - q_wh) / p.c_winding(), (q_wh - q_ha) / p.c_housing())
            }
            None => (0.0, 0.0),
        }
    }

    /// The heat flow from joint j's housing to the ambient, `(T_h − T_a) / R_th2`, W.
    #[inline]
    pub fn heat_to_ambient(&self, j: usize, t_h: f64) -> f64 {
        self.params[j].as_ref().map_or(0.0, |p| (t_h - self.ambient) / p.r_housing_ambient)
    }

    /// The heat stored in joint j's motor since t = 0, `C_w (T_w − T_0) + C_h (T_h − T_0)`, J.
    pub fn stored_heat(&self, j: usize, t_w: f64, t_h: f64) -> f64 {
        self.params[j].as_ref().map_or(0.0, |p| p.c_winding() * (t_w - self.initial) + p.c_housing() * (t_h - self.initial))
    }
}

/// The two-node network's response to a constant copper loss `p` (W) from `T_w = T_h = T_0`
/// with `T_a = T_0` (no heat while at rest), at time `t` (s): `(T_w − T_0, T_h − T_0)`, K. The
/// closed form of a linear ODE `ẋ = A x + b` (x = the two rises): `x(t) = x_∞ + Σ_k c_k v_k e^{λ_k t}`
/// with the eigenpairs of A (real, negative: A is similar to a symmetric negative definite
/// matrix) and x_∞ = (p (R_th1 + R_th2), p R_th2). A stalled motor at constant current with
/// α = 0 (a constant copper loss R i²) is this problem.
pub fn step_response(p: &ThermalParams, heat: f64, t: f64) -> (f64, f64) {
    let (cw, ch, r1, r2) = (p.c_winding(), p.c_housing(), p.r_winding_housing, p.r_housing_ambient);
    // A = [[-1/(r1 cw), 1/(r1 cw)], [1/(r1 ch), -(1/r1 + 1/r2)/ch]]
    let (a11, a12, a21, a22) = (-1.0 / (r1 * cw), 1.0 / (r1 * cw), 1.0 / (r1 * ch), -(1.0 / r1 + 1.0 / r2) / ch);
    let tr = a11 + a22;
    let det = a11 * a22 - a12 * a21;
    let disc = (tr * tr / 4.0 - det).sqrt();
    let (l1, l2) = (tr / 2.0 + disc, tr / 2.0 - disc);
    let (xw_inf, xh_inf) = (heat * (r1 + r2), heat * r2);
    // eigenvectors (a12, λ − a11); x(0) − x_∞ = −x_∞ = c1 v1 + c2 v2
    let (v1, v2) = ((a12, l1 - a11), (a12, l2 - a11));
    let (bw, bh) = (-xw_inf, -xh_inf);
    let d = v1.0 * v2.1 - v2.0 * v1.1;
    let c1 = (bw * v2.1 - v2.0 * bh) / d;
    let c2 = (v1.0 * bh - bw * v1.1) / d;
    let (e1, e2) = ((l1 * t).exp(), (l2 * t).exp());
    (xw_inf + c1 * v1.0 * e1 + c2 * v2.0 * e2, xh_inf + c1 * v1.1 * e1 + c2 * v2.1 * e2)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn re40() -> ThermalParams {
        ThermalParams {
            r_winding_housing: 1.93,
            r_housing_ambient: 4.65,
            tau_winding: 41.6,
            tau_housing: 1120.0,
            max_winding_temperature: 155.0,
            reference_temperature: 25.0,
            alpha_20: ALPHA_COPPER_20,
        }
    }

    /// R(T_ref) = R_ref exactly; R(20 °C) = R_ref / (1 + 5 α); the slope is the difference
    /// quotient (a linear law: to rounding).
    #[test]
    fn resistance_is_linear_in_temperature_and_equals_the_datasheet_value_at_its_reference() {
        let p = re40();
        assert_eq!(p.resistance_factor(25.0), 1.0);
        assert!((p.resistance_factor(20.0) - 1.0 / (1.0 + 5.0 * 0.00393)).abs() < 1e-15);
        // 100 K above the reference: +37.55 % (α_25 = 0.00393 / 1.01965 = 0.0038543 /K)
        assert!((p.resistance_factor(125.0) - (1.0 + 100.0 * 0.00393 / 1.01965)).abs() < 1e-12);
        assert!(((p.resistance_factor(80.0) - p.resistance_factor(30.0)) / 50.0 - p.resistance_slope()).abs() < 1e-15);
    }

    /// C_w = τ_w / R_th1 and C_h = τ_s / R_th2 (the RE 40's: 21.55 J/K and 240.9 J/K), and at
    /// steady state under a constant loss p: T_w − T_a = p (R_th1 + R_th2), T_h − T_a = p R_th2
    /// (the rates vanish there, and the closed form tends to it).
    #[test]
    fn capacities_and_the_steady_state_follow_the_catalogue_convention() {
        let p = re40();
        assert!((p.c_winding() - 41.6 / 1.93).abs() < 1e-12 && (p.c_housing() - 1120.0 / 4.65).abs() < 1e-12);
        let th = Thermal { params: vec![Some(p)], ambient: 25.0, initial: 25.0, r_ref: vec![1.16] };
        let (tw, thh) = (25.0 + 10.0 * (1.93 + 4.65), 25.0 + 10.0 * 4.65);
        let (a, b) = th.rates(0, 10.0, tw, thh);
        assert!(a.abs() < 1e-14 && b.abs() < 1e-14, "{a} {b}");
        let (xw, xh) = step_response(&p, 10.0, 1e6);
        assert!((xw - 65.8).abs() < 1e-9 && (xh - 46.5).abs() < 1e-9, "{xw} {xh}");
        let (xw0, xh0) = step_response(&p, 10.0, 0.0);
        assert!(xw0.abs() < 1e-12 && xh0.abs() < 1e-12, "{xw0} {xh0}");
        // the closed form satisfies the ODE: central differences of x(t) against the rates
        for &t in &[1.0, 40.0, 600.0] {
            let h = 1e-3;
            let (xp, xm, x) = (step_response(&p, 10.0, t + h), step_response(&p, 10.0, t - h), step_response(&p, 10.0, t));
            let (dw, dh) = ((xp.0 - xm.0) / (2.0 * h), (xp.1 - xm.1) / (2.0 * h));
            let (rw, rh) = th.rates(0, 10.0, 25.0 + x.0, 25.0 + x.1);
            assert!((dw - rw).abs() < 1e-7 && (dh - rh).abs() < 1e-7, "t = {t}: {dw} {rw} {dh} {rh}");
        }
    }
}
