//! Index ranges of the state vector (the module docs of `ode` give the layout).

use crate::dynamics::motor::Electrical;

/// The quadratures each contact adds to the state ([`Layout::contact_quadratures`]).
pub const QUADRATURES_PER_CONTACT: usize = 3;

/// Index ranges of the state vector.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Layout {
    pub nv: usize,
    /// The motors' electrical model: whether the currents are states.
    pub electrical: Electrical,
    /// The conversion quadrature `E_conv = ∫ Σ (K_e − K_t) k i q̇ dt` is present (some K_e ≠
    /// K_t); it follows the three losses.
    pub conversion: bool,
    /// The stops' damping loss `E_s = ∫ Σ c q̇² [beyond] dt` is present (soft stops
    /// configured); it comes last.
    pub stops: bool,
    /// Number of contacts with energy quadratures: every contact of a run that has a
    /// non-bilateral contact (0 otherwise, so the paper's layout is unchanged). Per contact k,
    /// three follow the stops': impact loss, friction work, damping loss.
    pub contacts: usize,
    /// The thermal model is on (`dynamics/thermal.rs`): the winding and housing temperatures
    /// of every motor follow the currents (2 nv states, before the quadratures, since R(T_w)
    /// feeds back into the currents), and the heat to the ambient `Q_a` comes last.
    pub thermal: bool,
    /// The gears' Coulomb and efficiency loss `E_g` is present (`gear_friction`); it follows
    /// the contacts' quadratures.
    pub gear: bool,
    /// The supply's four quadratures (energy delivered, regenerated, dumped, conversion loss)
    /// are present (`supply`); they follow `E_g` (and come before `Q_a`).
    pub supply: bool,
}

impl Layout {
    /// Number of current states: nv, or 0 for quasi-static motors.
    pub fn ni(&self) -> usize {
        self.electrical.states(self.nv)
    }
    /// Number of temperature states: 2 nv with the thermal model, else 0.
    pub fn nth(&self) -> usize {
        if self.thermal { 2 * self.nv } else { 0 }
    }
    /// Where the quadratures start: after q, q̇, the currents and the temperatures.
    fn head(&self) -> usize {
        2 * self.nv + self.ni() + self.nth()
    }
    pub fn dim(&self) -> usize {
        self.head() + 2 * self.nv + 3 + usize::from(self.conversion) + usize::from(self.stops) + 3 * self.contacts + usize::from(self.gear) + 4 * usize::from(self.supply) + usize::from(self.thermal)
    }
    /// `E_g`, when [`Layout::gear`].
    pub fn loss_gear(&self) -> Option<usize> {
        self.gear.then(|| self.impact_loss(self.contacts))
    }
    /// The first of the supply's `E_supply, E_regen, E_dump, E_sloss`, when [`Layout::supply`].
    pub fn supply(&self) -> Option<usize> {
        self.supply.then(|| self.impact_loss(self.contacts) + usize::from(self.gear))
    }
    pub fn q(&self) -> std::ops::Range<usize> {
        0..self.nv
    }
    pub fn qd(&self) -> std::ops::Range<usize> {
        self.nv..2 * self.nv
    }
    /// The currents; empty for quasi-static motors.
    pub fn current(&self) -> std::ops::Range<usize> {
        2 * self.nv..2 * self.nv + self.ni()
    }
    /// The winding temperatures T_w, °C; empty without the thermal model.
    pub fn winding_temperature(&self) -> std::ops::Range<usize> {
        let s = 2 * self.nv + self.ni();
        s..s + self.nth() / 2
    }
    /// The housing temperatures T_h, °C; empty without the thermal model.
    pub fn housing_temperature(&self) -> std::ops::Range<usize> {
        let s = 2 * self.nv + self.ni() + self.nth() / 2;
        s..s + self.nth() / 2
    }
    /// `Q_a = ∫ Σ (T_h − T_a) / R_th2 dt`, the heat given to the ambient, J: the last
    /// component, with the thermal model.
    pub fn heat_to_ambient(&self) -> Option<usize> {
        self.thermal.then(|| self.dim() - 1)
    }
    pub fn work(&self) -> std::ops::Range<usize> {
        let s = self.head();
        s..s + self.nv
    }
    pub fn electric(&self) -> std::ops::Range<usize> {
        let s = self.head() + self.nv;
        s..s + self.nv
    }
    pub fn loss_r(&self) -> usize {
        self.head() + 2 * self.nv
    }
    /// `∫ Σ D_j q̇_j² dt`: the joints' own viscous friction.
    pub fn loss_d(&self) -> usize {
        self.loss_r() + 1
    }
    /// `∫ Σ D_m,j q̇_j² dt`: the gears' viscous friction, seen at the joint.
    pub fn loss_dm(&self) -> usize {
        self.loss_r() + 2
    }
    /// `E_conv`, when [`Layout::conversion`].
    pub fn loss_conversion(&self) -> Option<usize> {
        self.conversion.then(|| self.loss_r() + 3)
    }
    /// `E_s`, when [`Layout::stops`].
    pub fn loss_stop(&self) -> Option<usize> {
        self.stops.then(|| self.loss_r() + 3 + usize::from(self.conversion))
    }
    /// Contact k's kinetic energy lost in impacts (with the rotors'), J.
    pub fn impact_loss(&self, k: usize) -> usize {
        self.loss_r() + 3 + usize::from(self.conversion) + usize::from(self.stops) + 3 * k
    }
    /// Contact k's three quadratures: impact loss, friction work, damping loss.
    pub fn contact_quadratures(&self, k: usize) -> [usize; QUADRATURES_PER_CONTACT] {
        [self.impact_loss(k), self.friction_work(k), self.damping_loss(k)]
    }
    /// Contact k's friction work `∫ −f_t · v_t dt`, J.
    pub fn friction_work(&self, k: usize) -> usize {
        self.impact_loss(k) + 1
    }
    /// Contact k's damping loss `∫ (f_n − k δ) δ̇ dt` (compliant contacts), J.
    pub fn damping_loss(&self, k: usize) -> usize {
        self.impact_loss(k) + 2
    }
    /// A readable name of state component `k`, for error messages.
    pub fn name(&self, k: usize, joints: &[String]) -> String {
        let within = |r: std::ops::Range<usize>| r.contains(&k).then(|| joints[k - r.start].clone());
        if let Some(j) = within(self.q()) {
            format!("q of {j}")
        } else if let Some(j) = within(self.qd()) {
            format!("q' of {j}")
        } else if let Some(j) = within(self.current()) {
            format!("current of {j}")
        } else if let Some(j) = within(self.winding_temperature()) {
            format!("winding temperature of {j}")
        } else if let Some(j) = within(self.housing_temperature()) {
            format!("housing temperature of {j}")
        } else if Some(k) == self.heat_to_ambient() {
            "heat to the ambient".into()
        } else if let Some(j) = within(self.work()) {
            format!("link work of {j}")
        } else if let Some(j) = within(self.electric()) {
            format!("electric energy of {j}")
        } else if k == self.loss_r() {
            "resistive loss".into()
        } else if k == self.loss_d() {
            "joint friction loss".into()
        } else if k == self.loss_dm() {
            "gear friction loss".into()
        } else if Some(k) == self.loss_conversion() {
            "back-EMF conversion energy".into()
        } else if Some(k) == self.loss_stop() {
            "joint stop damping loss".into()
        } else if Some(k) == self.loss_gear() {
            "gear Coulomb and efficiency loss".into()
        } else if let Some(s) = self.supply().filter(|&s| k >= s) {
            ["supply energy", "supply energy regenerated", "supply energy dumped", "supply conversion loss"][(k - s).min(3)].into()
        } else {
            let first = self.impact_loss(0);
            let c = (k - first) / 3;
            ["impact loss", "friction work", "damping loss"][(k - first) % 3].to_string() + &format!(" of contact {c}")
        }
    }
}
