//! RODAS's `J` and `f_t` at the start of a step ([`super::Rodas`]; split from `rodas.rs` for
//! its size): the system's exact Jacobian, else forward differences over the coupled columns
//! with the system's exact trailing columns (the arm's currents) written after them, and the
//! exact `∂f/∂t` where the system has it (the module docs of `rodas.rs`).

use super::{fd_floor, Rodas};
use crate::integrate::jacobian::{fd_jacobian_column_range_within, DifferenceIncrement};
use crate::integrate::rosenbrock::time_derivative;
use crate::integrate::{first_non_finite, IntegrateError, OdeJacobian, Phase};

impl Rodas {
    /// `J` at the current point: the system's exact one, else forward differences over the
    /// coupled columns.
    pub(super) fn evaluate_jacobian<S: OdeJacobian>(
        &mut self,
        sys: &mut S,
    ) -> Result<(), IntegrateError<S::Error>> {
        let (t, n, nc) = (self.core.t, self.dim, self.nc);
        self.core.stats.jacobian_evals += 1;
        let exact = sys
            .exact_jacobian(t, &self.y, &self.f0, &mut self.jac)
            .map_err(IntegrateError::Rhs)?;
        if exact {
            self.jac_tail_zero = false;
        } else {
            if !self.jac_tail_zero {
                self.jac.fill(0.0);
                self.jac_tail_zero = true;
            }
            let inc = sys.difference_increment().unwrap_or(DifferenceIncrement { noise: f64::EPSILON, floor: fd_floor(&self.core.control) });
            // the leading columns by differences, the trailing ones exact where the system can
            let k = sys.exact_columns_start().min(nc);
            self.difference_columns(sys, 0..k, inc)?;
            if k < nc {
                // the system's own evaluations for the columns count whether it writes them or
                // declines (`Stats::rhs_evals`)
                self.core.stats.rhs_evals += sys.exact_columns_rhs_evals();
                if !sys.exact_columns(t, &self.y, &self.f0, &mut self.jac).map_err(IntegrateError::Rhs)? {
                    self.difference_columns(sys, k..nc, inc)?;
                }
            }
        }
        // the first non-finite entry's row and the largest |entry|, over the columns written
        // (the others are 0)
        let cols = if exact { n } else { nc };
        let mut jac_max = 0.0f64;
        self.quad_rows.clear();
        for r in 0..n {
            let row = &self.jac[r * n..r * n + cols];
            if first_non_finite(row).is_some() {
                return Err(IntegrateError::NonFiniteState { t, index: r });
            }
            jac_max = row.iter().fold(jac_max, |m, v| m.max(v.abs()));
            if r >= nc && self.jac[r * n..r * n + nc].iter().any(|&v| v != 0.0) {
                self.quad_rows.push(r);
            }
        }
        self.jac_max = jac_max;
        self.jac_valid = true;
        self.jac_fresh = true;
        self.steps_since_jac = 0;
        self.lu_h = f64::NAN;
        Ok(())
    }

    /// The difference columns `cols` of `J` at the current point, counted in
    /// `Stats::rhs_evals`; [`IntegrateError::OutOfTime`] past the deadline.
    pub(super) fn difference_columns<S: OdeJacobian>(
        &mut self,
        sys: &mut S,
        cols: std::ops::Range<usize>,
        inc: DifferenceIncrement,
    ) -> Result<(), IntegrateError<S::Error>> {
        let (t, nc, start) = (self.core.t, self.nc, cols.start);
        let stopped = fd_jacobian_column_range_within(
            sys,
            t,
            &self.y,
            &self.f0,
            &mut self.jac,
            cols.clone(),
            inc,
            &mut self.y_stage,
            &mut self.f_stage,
            self.watch,
        )
        .map_err(IntegrateError::Rhs)?;
        if let Some(j) = stopped {
            self.core.stats.rhs_evals += (j - start) as u64;
            self.jac_valid = false;
            return Err(IntegrateError::OutOfTime { t, during: Phase::Jacobian { column: j + 1, columns: nc } });
        }
        self.core.stats.rhs_evals += cols.len() as u64;
        Ok(())
    }

    /// `f_t` at the current point ([`crate::integrate::rosenbrock::time_derivative`]).
    pub(super) fn evaluate_dfdt<S: OdeJacobian>(
        &mut self,
        sys: &mut S,
    ) -> Result<(), IntegrateError<S::Error>> {
        let t = self.core.t;
        if sys.exact_time_derivative(t, &self.y, &self.f0, &mut self.dfdt).map_err(IntegrateError::Rhs)? {
            if let Some(i) = first_non_finite(&self.dfdt) {
                return Err(IntegrateError::NonFiniteState { t, index: i });
            }
        } else {
            time_derivative(&mut self.core.stats, sys, t, &self.y, &self.f0, &mut self.dfdt, &mut self.f_stage)?;
        }
        self.dfdt_fresh = true;
        Ok(())
    }
}
