//! Mechanical energies for the energy balance of SCENE.md: kinetic `T = ½ Σ v_i · I_i v_i`
//! (spatial form, RBDA §2.13) plus the reflected rotor `½ Σ J_m q̇^2`, and potential
//! `V = −Σ m_i g · c_i` (c_i the world centre of mass).

use super::data::Data;
use super::model::Model;
use super::motor::Drives;

/// Kinetic energy of the links from the body velocities of the last `rnea` call, J.
pub fn link_kinetic_energy(model: &Model, data: &Data) -> f64 {
    model
        .bodies
        .iter()
        .enumerate()
        .map(|(i, b)| 0.5 * b.inertia.mul(&data.v_body[i]).dot(&data.v_body[i]))
        .sum()
}

/// Kinetic energy of the rotors seen through their gears, `½ Σ J_m q̇^2`, J.
pub fn rotor_kinetic_energy(drives: &Drives, qd: &[f64]) -> f64 {
    qd.iter().zip(drives.jm.iter()).map(|(w, jm)| 0.5 * jm * w * w).sum()
}

/// Gravitational potential energy relative to the world origin, J. Needs `forward_kinematics`.
pub fn potential_energy(model: &Model, data: &Data) -> f64 {
    model
        .bodies
        .iter()
        .enumerate()
        .map(|(i, b)| {
            let c_world = data.x_world_body[i] * nalgebra::Point3::from(b.inertia.com());
            -b.inertia.mass * model.gravity.dot(&c_world.coords)
        })
        .sum()
}

/// Magnetic energy stored in the armature inductances, `½ Σ L i^2`, J.
pub fn magnetic_energy(drives: &Drives, current: &[f64]) -> f64 {
    current.iter().zip(drives.l.iter()).map(|(i, l)| 0.5 * l * i * i).sum()
}
