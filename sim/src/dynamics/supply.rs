//! The electric supply behind the drives: what it delivers for the electric powers
//! `p_j = i_j v_j` the motors draw (eq 11's terminal power), with or without regeneration, and
//! with an optional shared DC bus.
//!
//! Each drive's amplifier (an ideal switch-mode stage, `motor.rs`) puts on its DC side
//! - with **regeneration** on: `a_j = p_j` (power from a braking motor goes back to the DC side);
//! - without: `a_j = max(p_j, 0)`; the braking power `max(−p_j, 0)` is turned into heat in the
//!   drive's brake (shunt) resistor: `dump_j = a_j − p_j`.
//!
//! Without a shared bus each drive has its own ideal supply, which delivers `a_j`; the supply
//! power is `P_s = Σ a_j`. With a **shared DC bus** the drives' DC powers meet on the bus first,
//! so a braking joint feeds a driving one: the bus needs `P_b = Σ a_j`, and its supply (a
//! rectifier or a DC source of efficiency η_s) delivers
//! - `P_s = P_b / η_s` when `P_b ≥ 0`;
//! - when `P_b < 0` (the bus has a surplus): `P_s = η_s P_b` (< 0: energy returned to the mains
//!   or the battery) if the supply regenerates, else `P_s = 0` and the surplus `−P_b` is dumped in
//!   the bus's brake resistor.
//!
//! The supply's conversion loss is `P_s − P_b` (≥ 0 in both directions). Summed:
//! `P_s = Σ p_j + Σ dump_j + dump_bus + loss_s` exactly, so `E_supply = Σ E_j + E_dumped +
//! E_supply_loss` holds as an identity of the quadratures (`ode/drive_modes.rs` integrates them,
//! each max() in its own smooth phase: an event at every sign change of `p_j` and `P_b`); the
//! energy regenerated is `∫ max(−P_s, 0) dt` (what the supply takes back).
//!
//! Sources: the drive-side brake chopper and the common DC bus of multi-axis servo drives,
//! Mohan, Undeland & Robbins, *Power Electronics*, 3rd ed., Wiley 2003, §13-5 (regenerative
//! braking of a DC drive; dissipative braking in a resistor) and §8-7 (the DC-link of a
//! drive); Rockwell Automation, *Kinetix 5700 Servo Drives User Manual* 2198-UM002, "shared
//! DC bus" and "shunt resistor"; the robot-energy literature that counts only positive supply
//! power without regeneration: Carabin, Wehrle & Vidoni, *A review on energy-saving
//! optimization methods for robotic and automatic systems*, Robotics 6 (2017) 39, §2.

/// The supply of a scene's drives, validated ([`crate::scene`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Supply {
    /// Per joint: its amplifier returns braking power to the DC side.
    pub regeneration: Vec<bool>,
    /// The shared DC bus, if any.
    pub bus: Option<Bus>,
}

/// A shared DC bus and its supply.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bus {
    /// η_s: the supply's efficiency, 0 < η_s ≤ 1.
    pub efficiency: f64,
    /// The supply takes a surplus back (else the bus's brake resistor dumps it).
    pub regeneration: bool,
}

/// The powers at one instant, W. `sign_*` are the sides the max() functions take (the modes,
/// so that a phase between events is smooth; see [`Supply::powers`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SupplyPowers {
    /// `P_s`, W.
    pub supply: f64,
    /// `P_b = Σ a_j`, W.
    pub bus: f64,
    /// `Σ dump_j + dump_bus`, W.
    pub dumped: f64,
    /// `P_s − P_b` (0 without a bus), W.
    pub loss: f64,
    /// `max(−P_s, 0)`, W (by the bus side: `−P_s` while P_b is taken as < 0).
    pub regenerated: f64,
}

impl Supply {
    /// Whether joint j's power needs an event at its sign change (its amplifier clips it).
    pub fn clips(&self, j: usize) -> bool {
        !self.regeneration[j]
    }

    /// The powers for the motors' `p` with the sides given by the modes: `pos[j]` (joint j's
    /// power is taken as ≥ 0, for the clipping drives) and `bus_pos` (the bus power as ≥ 0).
    /// At the true signs this is the law of the module docs; the event functions
    /// (`ode/drive_modes.rs`) say when a side is left.
    pub fn powers(&self, p: &[f64], pos: &[bool], bus_pos: bool) -> SupplyPowers {
        let mut bus = 0.0;
        let mut dumped = 0.0;
        for (j, &pj) in p.iter().enumerate() {
            if self.regeneration[j] || pos[j] {
                bus += pj;
            } else {
                dumped -= pj;
            }
        }
        let (supply, loss) = match self.bus {
            None => (bus, 0.0),
            Some(b) => {
                let s = if bus_pos {
                    bus / b.efficiency
                } else if b.regeneration {
                    b.efficiency * bus
                } else {
                    dumped -= bus;
                    0.0
                };
                (s, s - if bus_pos || b.regeneration { bus } else { 0.0 })
            }
        };
        SupplyPowers { supply, bus, dumped, loss, regenerated: if bus_pos { 0.0 } else { -supply } }
    }

    /// The sides at the true signs of `p` (and of the bus power that follows).
    pub fn sides(&self, p: &[f64], pos: &mut [bool]) -> bool {
        for (j, &pj) in p.iter().enumerate() {
            pos[j] = pj >= 0.0;
        }
        let bus: f64 = p.iter().enumerate().map(|(j, &pj)| if self.regeneration[j] || pj >= 0.0 { pj } else { 0.0 }).sum();
        bus >= 0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `P_s = Σ p_j + dumped + loss` at the true sides, every configuration, and the hand values.
    #[test]
    fn the_supply_identity_and_hand_values() {
        let p = [30.0, -50.0, 5.0];
        for regen in [[true, true, true], [false, false, false], [true, false, true]] {
            for bus in [None, Some(Bus { efficiency: 0.9, regeneration: true }), Some(Bus { efficiency: 0.8, regeneration: false })] {
                let s = Supply { regeneration: regen.to_vec(), bus };
                let mut pos = [false; 3];
                let bus_pos = s.sides(&p, &mut pos);
                let w = s.powers(&p, &pos, bus_pos);
                let sum: f64 = p.iter().sum();
                assert!((w.supply - (sum + w.dumped + w.loss)).abs() < 1e-12, "{regen:?} {bus:?}: {w:?}");
                assert!(w.dumped >= 0.0 && w.loss >= -1e-12);
            }
        }
        // all regenerating on a bus of 0.9: P_b = −15 W, the supply takes back 13.5 W
        let s = Supply { regeneration: vec![true; 3], bus: Some(Bus { efficiency: 0.9, regeneration: true }) };
        let mut pos = [false; 3];
        let bus_pos = s.sides(&p, &mut pos);
        let w = s.powers(&p, &pos, bus_pos);
        assert!((w.supply + 13.5).abs() < 1e-12 && (w.regenerated - 13.5).abs() < 1e-12);
        // no regeneration anywhere, separate supplies: 35 W delivered, 50 W dumped
        let s = Supply { regeneration: vec![false; 3], bus: None };
        let bus_pos = s.sides(&p, &mut pos);
        let w = s.powers(&p, &pos, bus_pos);
        assert!((w.supply - 35.0).abs() < 1e-12 && (w.dumped - 50.0).abs() < 1e-12 && w.regenerated == 0.0);
    }
}
