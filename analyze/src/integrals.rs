//! Energy integrals recomputed from the recorded samples, to check the ones the simulator
//! integrated (`/energy`).
//!
//! The simulator integrates `E_j = ∫ i_j v_j dt` and `W_j = ∫ τ_j q'_j dt` as quadrature states
//! of the ODE, at the integrator's accuracy (SCENE.md "Energy balance"). From the recording
//! alone they can be recomputed by the composite trapezoid rule over the output grid,
//!
//! ```text
//! I_h = Σ_k (t_{k+1} - t_k) (p_k + p_{k+1}) / 2,   p = i_j v_j  (/motors current, voltage)
//!                                                p = τ_j q'_j  (/motors torque, /joint_states velocity)
//! ```
//!
//! whose error on a uniform grid is `-(T h² / 12) p''(ξ)` (Süli & Mayers, *An Introduction to
//! Numerical Analysis*, 2003, §7.5, Theorem 7.3). The same rule on every second sample, `I_2h`,
//! gives Richardson's estimate of that error, `I - I_h ≈ (I_h - I_2h) / 3` (§7.7), which
//! [`SampledIntegrals`] reports beside the difference to the recorded value: the recorded
//! integrals agree with the samples when `|I_h - I_recorded|` is of the size of that estimate
//! ([`SampledIntegrals::agrees`]). For the estimate to hold, `p` must be smooth on the scale of
//! `2h`. It is not during the paper arm's start-up: the PD law starts at −222 V on the wrist
//! motor and its light links ring faster than 0.1 ms, so over the whole run the samples (even
//! at 8 kHz) miss joules of E_9 and E_10; [`sampled_integrals_from`] checks the run after such a
//! transient, where the samples converge as h².

use schemas::{topics, EnergyState, JointState, MotorState, Recording};
use serde::{Deserialize, Serialize};

use crate::Error;

/// One integral of one joint, J.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SampledIntegral {
    /// The simulator's value at the last sample minus at the first (`/energy`).
    pub recorded_j: f64,
    /// Trapezoid rule over every sample, `I_h`.
    pub sampled_j: f64,
    /// Richardson's estimate of the error of `I_h`, `(I_h - I_2h) / 3` (0 with fewer than 3
    /// samples).
    pub sampling_error_j: f64,
}

impl SampledIntegral {
    /// `|I_h - I_recorded|`.
    pub fn difference_j(&self) -> f64 {
        (self.sampled_j - self.recorded_j).abs()
    }
}

/// `|I_h - I_recorded|` within this many Richardson estimates counts as agreement ...
pub const AGREEMENT_FACTOR: f64 = 3.0;
/// ... or within this fraction of `Σ_j |I_j|` (the run's total of that kind of integral): the
/// recorded integrals and the samples both come from the integrator's dense output, whose own
/// error (about rtol of the scale) is far below this and far below any sampling error worth
/// telling.
pub const AGREEMENT_FLOOR: f64 = 1e-7;

impl SampledIntegrals {
    /// Does each recomputed integral agree with the recorded one within its sampling error
    /// ([`AGREEMENT_FACTOR`] Richardson estimates, or [`AGREEMENT_FLOOR`] of the total)?
    pub fn agrees(&self) -> bool {
        self.disagreeing().is_empty()
    }

    /// The integrals that do not agree: `("E" | "W", joint)`.
    pub fn disagreeing(&self) -> Vec<(&'static str, &str)> {
        let mut out = Vec::new();
        for (kind, list) in [("E", &self.electric), ("W", &self.work)] {
            let floor = AGREEMENT_FLOOR * list.iter().map(|i| i.recorded_j.abs()).sum::<f64>();
            for (i, joint) in list.iter().zip(&self.joints) {
                if i.difference_j() > AGREEMENT_FACTOR * i.sampling_error_j.abs() + floor {
                    out.push((kind, joint.as_str()));
                }
            }
        }
        out
    }
}

/// `E_j` and `W_j` of every joint recomputed from the samples.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SampledIntegrals {
    /// Start of the window checked, s (the first sample at or after the time asked).
    pub from_s: f64,
    /// Output step, s (the first interval; the grid is uniform).
    pub dt_s: f64,
    pub joints: Vec<String>,
    /// `∫ i_j v_j dt`, one per joint.
    pub electric: Vec<SampledIntegral>,
    /// `∫ τ_j q'_j dt`, one per joint.
    pub work: Vec<SampledIntegral>,
}

/// Trapezoid rule over `(t_k, p_k)`, and over every second sample (`None` below 3 samples).
pub fn trapezoid(t: &[f64], p: &[f64]) -> (f64, Option<f64>) {
    let fine = (1..t.len()).map(|k| (t[k] - t[k - 1]) * (p[k] + p[k - 1]) / 2.0).sum();
    if t.len() < 3 {
        return (fine, None);
    }
    // every second sample, and the last interval as it is when the count is even
    let mut coarse = 0.0;
    let mut k = 2;
    while k < t.len() {
        coarse += (t[k] - t[k - 2]) * (p[k] + p[k - 2]) / 2.0;
        k += 2;
    }
    if t.len().is_multiple_of(2) {
        let n = t.len() - 1;
        coarse += (t[n] - t[n - 1]) * (p[n] + p[n - 1]) / 2.0;
    }
    (fine, Some(coarse))
}

fn integral(t: &[f64], p: &[f64], recorded_j: f64) -> SampledIntegral {
    let (sampled_j, coarse) = trapezoid(t, p);
    SampledIntegral {
        recorded_j,
        sampled_j,
        sampling_error_j: coarse.map_or(0.0, |c| (sampled_j - c) / 3.0),
    }
}

/// Recomputes `E_j` and `W_j` from `/motors` (current, voltage, torque) and `/joint_states`
/// (velocity) and reads the recorded ones from `/energy`. The three topics must share their
/// sample times (every recording of `sim` does).
pub fn sampled_integrals(rec: &Recording) -> Result<SampledIntegrals, Error> {
    sampled_integrals_from(rec, 0.0)
}

/// [`sampled_integrals`] over the samples with `t >= from_s` only (both the trapezoid rule and
/// the recorded values, `I(t_end) - I(t_from)`): a start-up transient faster than the output
/// step (the paper arm's light wrist links ring for the first milliseconds) makes the samples
/// unable to reproduce the integral over the whole run, while after it they converge as h².
pub fn sampled_integrals_from(rec: &Recording, from_s: f64) -> Result<SampledIntegrals, Error> {
    let mut samples = IntegralSamples::default();
    rec.replay(&INTEGRAL_TOPICS, &mut samples)?;
    samples.integrals(rec, from_s)
}

/// The topics the check reads.
pub const INTEGRAL_TOPICS: [&str; 3] = [topics::MOTORS, topics::JOINT_STATES, topics::ENERGY];

/// The samples the check needs, as columns (`i_j v_j`, `τ_j`, `q'_j`, and the recorded `E_j`,
/// `W_j`): fed one message at a time ([`schemas::Visitor`]) from a recording in memory or
/// streamed from a file, so a long run costs 5 numbers per joint and sample, not its messages.
#[derive(Debug, Default)]
pub struct IntegralSamples {
    joints: Option<usize>,
    t: [Vec<f64>; 3],
    /// Per sample of `/motors`: `i_j v_j` and `τ_j`, row after row (`joints` per row).
    power: Vec<f64>,
    torque: Vec<f64>,
    /// Per sample of `/joint_states`: `q'_j`.
    velocity: Vec<f64>,
    /// Per sample of `/energy`: `E_j` and `W_j`.
    electric: Vec<f64>,
    work: Vec<f64>,
    /// `(topic, field)` of an array some message does not record for every joint.
    unrecorded: Option<(&'static str, &'static str)>,
}

impl schemas::Visitor for IntegralSamples {
    fn message(&mut self, m: schemas::DecodedMessage<'_>) -> Result<(), schemas::Error> {
        let sizes = m.sizes();
        match m.topic {
            topics::MOTORS => {
                let mo: MotorState = m.decode(sizes)?;
                let n = *self.joints.get_or_insert(mo.current.len());
                let full = |v: &[f64]| v.len() == n;
                if !(full(&mo.current) && full(&mo.voltage) && full(&mo.torque)) {
                    let field = if !full(&mo.voltage) { "voltage" } else if !full(&mo.torque) { "torque" } else { "current" };
                    self.unrecorded.get_or_insert((topics::MOTORS, field));
                    return Ok(());
                }
                self.t[0].push(m.t_s());
                self.power.extend(mo.current.iter().zip(&mo.voltage).map(|(i, v)| i * v));
                self.torque.extend_from_slice(&mo.torque);
            }
            topics::JOINT_STATES => {
                let q: JointState = m.decode(sizes)?;
                if self.joints.is_some_and(|n| q.velocity.len() != n) {
                    self.unrecorded.get_or_insert((topics::JOINT_STATES, "velocity"));
                    return Ok(());
                }
                self.t[1].push(m.t_s());
                self.velocity.extend_from_slice(&q.velocity);
            }
            topics::ENERGY => {
                let e: EnergyState = m.decode(sizes)?;
                if self.joints.is_some_and(|n| e.electric_energy.len() != n || e.link_work.len() != n) {
                    self.unrecorded.get_or_insert((topics::ENERGY, "joint's energies"));
                    return Ok(());
                }
                self.t[2].push(m.t_s());
                self.electric.extend_from_slice(&e.electric_energy);
                self.work.extend_from_slice(&e.link_work);
            }
            _ => {}
        }
        Ok(())
    }
}

impl IntegralSamples {
    /// The check over the samples with `t >= from_s`; `rec` gives the file and the joint names.
    pub fn integrals(&self, rec: &Recording, from_s: f64) -> Result<SampledIntegrals, Error> {
        let file = || rec.source.clone();
        let t = &self.t[0];
        if t.len() < 3 {
            // the error estimate needs every second sample of at least two intervals
            return Err(Error::Table {
                file: file(),
                detail: format!("{} has {} samples: at least 3 are needed to check the integrals", topics::MOTORS, t.len()),
            });
        }
        if let Some((topic, what)) = self.unrecorded {
            return Err(Error::Table { file: file(), detail: format!("{topic} does not record every {what}: cannot check the integrals") });
        }
        let which = if self.t[1] != *t {
            Some(topics::JOINT_STATES)
        } else if self.t[2] != *t {
            Some(topics::ENERGY)
        } else {
            None
        };
        if let Some(which) = which {
            return Err(Error::Table {
                file: file(),
                detail: format!("{which} is not sampled at the times of {}: cannot integrate their product", topics::MOTORS),
            });
        }
        let n = self.joints.unwrap_or(0);
        let rows = |v: &[f64], k: usize| v.len() == k * n;
        if !(rows(&self.power, t.len()) && rows(&self.torque, t.len()) && rows(&self.velocity, t.len()) && rows(&self.electric, t.len()) && rows(&self.work, t.len())) {
            return Err(Error::Table { file: file(), detail: "the arrays of /motors, /joint_states and /energy do not all have one entry per joint: cannot check the integrals".into() });
        }
        let joints = rec.run().ok().map(|r| r.joint_names).filter(|j| j.len() == n).unwrap_or_else(|| (1..=n).map(|k| format!("joint{k}")).collect());
        let first = t.iter().position(|&x| x >= from_s).unwrap_or(t.len());
        if t.len() - first < 3 {
            return Err(Error::Table {
                file: file(),
                detail: format!("fewer than 3 samples from t = {from_s} s on: cannot check the integrals"),
            });
        }
        let last = t.len() - 1;
        let ts = &t[first..];
        let at = |rows: &[f64], k: usize, j: usize| rows[k * n + j];
        let mut electric = Vec::with_capacity(n);
        let mut work = Vec::with_capacity(n);
        for j in 0..n {
            let p: Vec<f64> = (first..=last).map(|k| at(&self.power, k, j)).collect();
            electric.push(integral(ts, &p, at(&self.electric, last, j) - at(&self.electric, first, j)));
            let p: Vec<f64> = (first..=last).map(|k| at(&self.torque, k, j) * at(&self.velocity, k, j)).collect();
            work.push(integral(ts, &p, at(&self.work, last, j) - at(&self.work, first, j)));
        }
        Ok(SampledIntegrals { from_s: ts[0], dt_s: t[1] - t[0], joints, electric, work })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The trapezoid rule is exact for linear p; for p = t² on [0, 1] its error is h²/6, and
    /// Richardson's estimate from the half-rate rule recovers it exactly (the error is exactly
    /// quadratic in h for a quadratic p).
    #[test]
    fn trapezoid_error_and_its_estimate() {
        for n in [11usize, 12] {
            let t: Vec<f64> = (0..n).map(|k| k as f64 / (n - 1) as f64).collect();
            let lin: Vec<f64> = t.iter().map(|x| 3.0 * x + 1.0).collect();
            assert!((trapezoid(&t, &lin).0 - 2.5).abs() < 1e-14);
            let sq: Vec<f64> = t.iter().map(|x| x * x).collect();
            let s = integral(&t, &sq, 1.0 / 3.0);
            let h = t[1];
            assert!((s.sampled_j - 1.0 / 3.0 - h * h / 6.0).abs() < 1e-14, "n = {n}");
            if n % 2 == 1 {
                // uniform half-rate grid: the estimate is exact
                assert!((s.sampling_error_j - (1.0 / 3.0 - s.sampled_j)).abs() < 1e-14);
            } else {
                assert!((s.sampling_error_j / (1.0 / 3.0 - s.sampled_j) - 1.0).abs() < 0.2);
            }
        }
        assert_eq!(trapezoid(&[0.0, 1.0], &[1.0, 3.0]), (2.0, None));
    }
}
