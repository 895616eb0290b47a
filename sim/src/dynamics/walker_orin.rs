//! The paper's baseline (eqs 22–26): Walker and Orin's method 1, *Efficient Dynamic Computer
//! Simulation of Robotic Mechanisms*, ASME J. Dyn. Sys. Meas. Control 104 (1982) 205–211.
//! Column i of the joint-space inertia is inverse dynamics with q̇ = 0, g = 0 and q̈ = e_i
//! (eq 26), and the bias is inverse dynamics with q̈ = 0 (eq 25): n + 1 calls of the recursive
//! Newton–Euler algorithm, O(n^2) with a large constant. Kept as the paper-style reference
//! against which `crba` is checked and timed.

use nalgebra::{DMatrix, Vector3};

use super::data::Data;
use super::model::Model;
use super::rnea::rnea;

/// Joint-space inertia by n calls of RNEA (eq 26), stored in `data.m` (nv x nv, kg m^2).
/// Clobbers `data.tau`.
pub fn mass_matrix<'d>(model: &Model, data: &'d mut Data, q: &[f64]) -> &'d DMatrix<f64> {
    let nv = model.nv;
    let zeros = std::mem::take(&mut data.zeros_nv);
    let mut unit = std::mem::take(&mut data.unit_nv);
    let no_gravity = Vector3::zeros();
    for i in 0..nv {
        unit.fill(0.0);
        unit[i] = 1.0;
        rnea(model, data, q, zeros.as_slice(), unit.as_slice(), &no_gravity);
        for r in 0..nv {
            data.m[(r, i)] = data.tau[r];
        }
    }
    data.zeros_nv = zeros;
    data.unit_nv = unit;
    &data.m
}
