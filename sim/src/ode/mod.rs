//! The ODE of one run, in one module: the state layout ([`Layout`]), the right-hand side (the
//! paper's eq 21 with the PD law of eq 27 and the IK targets of eqs 28–29), the outputs recorded
//! at each sample ([`Outputs`]), the structured Jacobian and the implicit circuit solve of the
//! stiff methods, and the projection onto the constraints — all on one [`ArmSystem`] with one
//! preallocated [`workspace::Workspace`] (private fields), so no part reads what another part
//! happened to leave behind.
//!
//! State `y` (all that is integrated, nothing else), with n = nv:
//! `[ q (n) | q̇ (n) | i (n) | W (n) | E (n) | E_R | E_D | E_Dm ]` where the currents i are
//! present only for inductive motors ([`crate::dynamics::motor::Electrical`]), and
//! `W_j = ∫ τ_j q̇_j dt` (work of motor j on link j, τ of eq 12), `E_j = ∫ i_j v_j dt` (electric
//! energy into motor j), `E_R = ∫ Σ R i² dt`, `E_D = ∫ Σ D q̇² dt` (the joints' viscous friction)
//! and `E_Dm = ∫ Σ D_m q̇² dt` (the gears', eq 12's d_m term). The quadratures ride along with
//! the dynamics so that they are integrated to the same accuracy. Two more follow only in the
//! scenes that have them (so the paper's layout is unchanged): `E_conv = ∫ Σ (K_e − K_t) k i q̇
//! dt` when some back-EMF constant differs from the torque constant (`dynamics/motor.rs`), and
//! `E_s = ∫ Σ c q̇² [beyond a limit] dt` when soft joint stops are configured
//! (`joint_limits.rs`). After the contacts' quadratures, again only in the scenes that have
//! them (`drive_modes.rs`): the gears' Coulomb and efficiency loss `E_g` (`gear_friction`),
//! then the supply's `E_supply, E_regen, E_dump, E_sloss` (`supply`). With the motors' thermal
//! model on (`dynamics/thermal.rs`, scene `thermal`), the winding and housing temperatures
//! `T_w (n) | T_h (n)` follow the currents (R(T_w) feeds back into eq 11, so they are coupled
//! states, before the quadratures) and the heat given to the ambient `Q_a` comes last; the
//! copper loss `E_R` is then `∫ Σ R(T_w) i² dt`.
//!
//! Energy balance (SCENE.md; ideal constraints do no work):
//! `Σ E_j = ΔT + ΔV + Δ(½ Σ L i²) + E_R + E_D + E_Dm [+ E_conv] [+ ΔV_s + E_s] [+ E_g]`, T including
//! the rotors' `½ Σ J_m q̇²`, `V_s = Σ ½ k δ²` the stops' stored energy. The voltage that
//! enters `E_j = ∫ i v dt` is the one the motor sees, after the drive's current window and
//! supply saturation (the amplifier is ideal: it neither stores nor loses energy), so the
//! limits add no term. Passive joints have i = v = 0 and no rotor. The controller law only
//! chooses v: it adds no term. Its residual measures the integration error (and constraint
//! drift, which lets f_n work).
//!
//! The supply's quadratures close their own identity `E_supply = Σ E_j + E_dump + E_sloss`
//! (`dynamics/supply.rs`), reported as `SupplyOutput::residual`.
//!
//! Files: `layout.rs` (state indices), `workspace.rs` (the scratch), `arm.rs` (the system and
//! its right-hand side), `outputs.rs`, `jacobian.rs` (Rosenbrock's Jacobian, IMEX's split), `current_columns.rs` and `time_derivative.rs`
//! (RODAS's exact current columns and `∂f/∂t`),
//! `projection.rs`.

mod arm;
mod describe;
mod drive_forces;
mod drive_modes;
mod contact_events;
mod current_columns;
mod gear_decide;
mod gear_hold;
mod hybrid;
mod resolution;
mod jacobian;
mod layout;
mod outputs;
mod projection;
mod stop_slip;
mod time_derivative;
mod workspace;
mod zeno;

pub use arm::ArmSystem;
pub use drive_modes::GearEvent;
pub use layout::Layout;
pub use outputs::{OutputLevel, Outputs, SupplyOutput};
pub use hybrid::REBOUND_START;
#[cfg(test)]
mod hybrid_tests;
