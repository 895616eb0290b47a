//! Index ranges of the state vector (the module docs of `ode` give the layout).

use crate::dynamics::motor::Electrical;

/// Index ranges of the state vector.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Layout {
    pub nv: usize,
    /// The motors' electrical model: whether the currents are states.
    pub electrical: Electrical,
}

impl Layout {
    /// Number of current states: nv, or 0 for quasi-static motors.
    pub fn ni(&self) -> usize {
        self.electrical.states(self.nv)
    }
    pub fn dim(&self) -> usize {
        4 * self.nv + self.ni() + 3
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
    pub fn work(&self) -> std::ops::Range<usize> {
        let s = 2 * self.nv + self.ni();
        s..s + self.nv
    }
    pub fn electric(&self) -> std::ops::Range<usize> {
        let s = 3 * self.nv + self.ni();
        s..s + self.nv
    }
    pub fn loss_r(&self) -> usize {
        4 * self.nv + self.ni()
    }
    /// `∫ Σ D_j q̇_j² dt`: the joints' own viscous friction.
    pub fn loss_d(&self) -> usize {
        4 * self.nv + self.ni() + 1
    }
    /// `∫ Σ D_m,j q̇_j² dt`: the gears' viscous friction, seen at the joint.
    pub fn loss_dm(&self) -> usize {
        4 * self.nv + self.ni() + 2
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
        } else if let Some(j) = within(self.work()) {
            format!("link work of {j}")
        } else if let Some(j) = within(self.electric()) {
            format!("electric energy of {j}")
        } else if k == self.loss_r() {
            "resistive loss".into()
        } else if k == self.loss_d() {
            "joint friction loss".into()
        } else {
            "gear friction loss".into()
        }
    }
}
