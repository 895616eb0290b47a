//! What the stiff integrators need from the arm's ODE ([`ArmSystem`]):
//!
//! - [`OdeJacobian`]: a cheap structured approximation of ∂f/∂y that keeps exactly the stiff
//!   couplings — the PD voltage law into the armature circuit, the circuit's own `−R/L`, the
//!   back-EMF, and the motor torque through the constrained inverse inertia
//!   `M_c⁻¹ = M_J⁻¹ − M_J⁻¹ J_cᵀ (J_c M_J⁻¹ J_cᵀ)⁻¹ J_c M_J⁻¹` (frozen at the current q):
//!   `∂q̇/∂q̇ = I`; `∂q̈/∂i = M_c⁻¹ K_m`; `∂q̈/∂q̇ = −M_c⁻¹ (D + D_m)`;
//!   `∂i̇/∂q = −k_p/L`, `∂i̇/∂q̇ = −(k_d + K_m)/L`, `∂i̇/∂i = −R/L`. With quasi-static motors
//!   (L = 0) the current is eliminated: `∂q̈/∂q = −M_c⁻¹ K_m k_p/R`,
//!   `∂q̈/∂q̇ = −M_c⁻¹ (K_m (k_d + K_m)/R + D + D_m)`. Coriolis, gravity stiffness and the
//!   quadrature rows are left out: a Rosenbrock-W method keeps its order with any bounded
//!   approximation (Hairer & Wanner, *Solving ODEs II*, §IV.7), and these terms are not stiff.
//! - [`SplitSystem`]: the armature circuit `L di/dt = v − R i − K_m q̇` is linear in i with a
//!   diagonal matrix, so its implicit stage equation `z − γ f_I(z) = r` has the closed form
//!   `z_i = (r_i + γ (v − K_m q̇)/L) / (1 + γ R/L)` (v and q̇ from the explicit components of r),
//!   for an IMEX Runge–Kutta method (Ascher, Ruuth & Spiteri 1997; Kennedy & Carpenter 2003).

use nalgebra::{Cholesky, DMatrix};

use crate::dynamics::spd::solve_regularized;
use crate::error::RunError;
use crate::integrate::{OdeJacobian, OdeSystem, SplitSystem};
use crate::system::ArmSystem;

/// Scratch for the structured Jacobian, sized once.
#[derive(Clone, Debug)]
pub struct JacobianScratch {
    /// `M_c⁻¹` (nv x nv).
    pub minv: DMatrix<f64>,
    tmp: DMatrix<f64>,
    a: DMatrix<f64>,
    ayt: DMatrix<f64>,
    f: Vec<f64>,
}

impl JacobianScratch {
    pub fn new(nv: usize, nc: usize, dim: usize) -> Self {
        Self {
            minv: DMatrix::zeros(nv, nv),
            tmp: DMatrix::zeros(nv, nv),
            a: DMatrix::zeros(nc, nc),
            ayt: DMatrix::zeros(nc, nv),
            f: vec![0.0; dim],
        }
    }
}

impl ArmSystem<'_> {
    /// `M_c⁻¹` at the state of the last evaluation, into `self.jac.minv`.
    fn constrained_inverse_inertia(&mut self, t: f64) -> Result<(), RunError> {
        let nv = self.layout.nv;
        let nc = self.contacts.len();
        let d = &self.scene.drives;
        let js = &mut self.jac;
        // (self.scene is a shared reference; `d` does not borrow `self.jac`)
        js.tmp.copy_from(&self.data.m);
        for j in 0..nv {
            js.tmp[(j, j)] += d.jm[j];
        }
        let m = std::mem::replace(&mut js.tmp, DMatrix::zeros(0, 0));
        let Some(chol) = Cholesky::new(m) else {
            js.tmp = DMatrix::zeros(nv, nv);
            return Err(crate::error::DynamicsError::SingularMassMatrix { t }.into());
        };
        js.minv.fill_with_identity();
        chol.solve_mut(&mut js.minv);
        js.tmp = chol.unpack_dirty();
        if nc > 0 {
            // A⁻¹ Yᵀ with the same regularisation as the force solve (dynamics/spd.rs)
            js.ayt.tr_copy_from(&self.fd.y);
            if solve_regularized(&self.fd.a, &mut js.a, &mut js.ayt).is_some() {
                js.minv.gemm(-1.0, &self.fd.y, &js.ayt, 1.0);
            }
        }
        Ok(())
    }
}

impl OdeJacobian for ArmSystem<'_> {
    fn jacobian(&mut self, t: f64, y: &[f64], _fy: &[f64], jac: &mut [f64]) -> Result<(), RunError> {
        // the dynamics at (t, y): M, Y = M⁻¹Jᵀ and A are left in `data` and `fd`
        let mut f = std::mem::take(&mut self.jac.f);
        let r = self.rhs(t, y, &mut f);
        self.jac.f = f;
        r?;
        self.constrained_inverse_inertia(t)?;
        let l = self.layout;
        let (nv, dim) = (l.nv, l.dim());
        let scene = self.scene;
        let (d, g) = (&scene.drives, &scene.gains);
        jac.fill(0.0);
        let mut set = |row: usize, col: usize, v: f64| jac[row * dim + col] = v;
        for j in 0..nv {
            set(l.q().start + j, l.qd().start + j, 1.0);
        }
        let minv = &self.jac.minv;
        for r in 0..nv {
            for c in 0..nv {
                let m = minv[(r, c)];
                if l.ni > 0 {
                    set(l.qd().start + r, l.current().start + c, m * d.km[c]);
                    set(l.qd().start + r, l.qd().start + c, -m * (d.d[c] + d.dm[c]));
                } else {
                    set(l.qd().start + r, l.q().start + c, -m * d.km[c] * g.kp[c] / d.r[c]);
                    set(l.qd().start + r, l.qd().start + c, -m * (d.km[c] * (g.kd[c] + d.km[c]) / d.r[c] + d.d[c] + d.dm[c]));
                }
            }
        }
        if l.ni > 0 {
            for j in 0..nv {
                let row = l.current().start + j;
                set(row, l.q().start + j, -g.kp[j] / d.l[j]);
                set(row, l.qd().start + j, -(g.kd[j] + d.km[j]) / d.l[j]);
                set(row, l.current().start + j, -d.r[j] / d.l[j]);
            }
        }
        Ok(())
    }
}

impl SplitSystem for ArmSystem<'_> {
    fn rhs_split(&mut self, t: f64, y: &[f64], f_e: &mut [f64], f_i: &mut [f64]) -> Result<(), RunError> {
        self.rhs(t, y, f_e)?;
        f_i.fill(0.0);
        for k in self.layout.current() {
            f_i[k] = f_e[k];
            f_e[k] = 0.0;
        }
        Ok(())
    }

    fn solve_implicit(&mut self, t: f64, gamma: f64, r: &[f64], z: &mut [f64]) -> Result<(), RunError> {
        z.copy_from_slice(r);
        let l = self.layout;
        if l.ni == 0 {
            return Ok(());
        }
        // v(t, q, q̇) from the explicit components, then the closed form per motor
        let scene = self.scene;
        self.voltage_at(t, &r[l.q()], &r[l.qd()])?;
        let (d, voltage) = (&scene.drives, &self.voltage);
        for j in 0..l.nv {
            let k = l.current().start + j;
            let qd = r[l.qd().start + j];
            z[k] = (r[k] + gamma * (voltage[j] - d.km[j] * qd) / d.l[j]) / (1.0 + gamma * d.r[j] / d.l[j]);
        }
        Ok(())
    }
}
