//! Small hybrid test systems for the event driver: a point `[x, v]` with `x' = v`,
//! `v' = law.acc(t, y)`, whose events and mode switches a [`Law`] defines. Each toy is an
//! [`OdeSystem`], [`OdeJacobian`] (exact `J = [[0, 1], [0, 0]]`, `∂f/∂t` left to the stepper)
//! and [`SplitSystem`] (all explicit: `f_I = 0`, the implicit solve is `z = r`), so every
//! method can drive it.

use crate::integrate::test_problems::RhsFailure;
use crate::integrate::{
    ArkImex, DormandPrince45, HybridSystem, OdeJacobian, OdeSystem, Rk4, Rodas, RodasMethod, Rosenbrock, SplitSystem,
    StepControl, Stepper,
};

/// The mode-dependent part of a toy.
pub(super) trait Law {
    fn n(&self) -> usize;
    fn dir(&self, i: usize) -> i8;
    fn acc(&self, t: f64, y: &[f64]) -> f64;
    fn events(&self, t: f64, y: &[f64], out: &mut [f64]);
    /// Switches modes at an event; returns whether it changed `y`.
    fn handle(&mut self, t: f64, y: &mut [f64], fired: &[bool]) -> bool;
    /// [`HybridSystem::event_tolerance`] of every function. Default: not watched.
    fn watch(&self) -> Option<f64> {
        None
    }
    /// [`HybridSystem::event_departure`] of every function. Default: its tolerance.
    fn departure(&self) -> Option<f64> {
        self.watch()
    }
    /// The modes at the start; may move `y` (returns whether it did). Default: nothing.
    fn init(&mut self, _y: &mut [f64]) -> bool {
        false
    }
}

/// A toy system driven by a [`Law`], logging every handled event and counting evaluations.
pub(super) struct Toy<L: Law> {
    pub(super) law: L,
    /// (time, fired functions, state before the handler) of every handled event.
    pub(super) log: Vec<(f64, Vec<bool>, [f64; 2])>,
    pub(super) rhs_calls: u64,
    pub(super) event_calls: u64,
    pub(super) after_steps: u64,
}

impl<L: Law> Toy<L> {
    pub(super) fn new(law: L) -> Self {
        Toy { law, log: Vec::new(), rhs_calls: 0, event_calls: 0, after_steps: 0 }
    }

    /// Times of the handled events.
    pub(super) fn times(&self) -> Vec<f64> {
        self.log.iter().map(|e| e.0).collect()
    }
}

impl<L: Law> OdeSystem for Toy<L> {
    type Error = RhsFailure;
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&mut self, t: f64, y: &[f64], dydt: &mut [f64]) -> Result<(), RhsFailure> {
        self.rhs_calls += 1;
        dydt[0] = y[1];
        dydt[1] = self.law.acc(t, y);
        Ok(())
    }
}

impl<L: Law> OdeJacobian for Toy<L> {
    fn jacobian(&mut self, _t: f64, _y: &[f64], _fy: &[f64], jac: &mut [f64]) -> Result<(), RhsFailure> {
        jac.copy_from_slice(&[0.0, 1.0, 0.0, 0.0]);
        Ok(())
    }
}

impl<L: Law> SplitSystem for Toy<L> {
    fn rhs_split(&mut self, t: f64, y: &[f64], f_e: &mut [f64], f_i: &mut [f64]) -> Result<(), RhsFailure> {
        f_i.fill(0.0);
        self.rhs(t, y, f_e)
    }
    fn solve_implicit(&mut self, _t: f64, _gamma: f64, r: &[f64], z: &mut [f64]) -> Result<(), RhsFailure> {
        z.copy_from_slice(r);
        Ok(())
    }
}

impl<L: Law> HybridSystem for Toy<L> {
    fn n_events(&self) -> usize {
        self.law.n()
    }
    fn event_direction(&self, i: usize) -> i8 {
        self.law.dir(i)
    }
    fn events(&mut self, t: f64, y: &[f64], out: &mut [f64]) -> Result<(), RhsFailure> {
        self.event_calls += 1;
        self.law.events(t, y, out);
        Ok(())
    }
    fn init_modes(&mut self, _t: f64, y: &mut [f64]) -> Result<bool, RhsFailure> {
        Ok(self.law.init(y))
    }
    fn handle_events(&mut self, t: f64, y: &mut [f64], fired: &[bool]) -> Result<bool, RhsFailure> {
        self.log.push((t, fired.to_vec(), [y[0], y[1]]));
        Ok(self.law.handle(t, y, fired))
    }
    fn after_step(&mut self, _t: f64, _y: &[f64]) {
        self.after_steps += 1;
    }
    fn event_tolerance(&self, _i: usize) -> Option<f64> {
        self.law.watch()
    }
    fn event_departure(&self, _i: usize) -> Option<f64> {
        self.law.departure()
    }
    // the toys exercise the restarts that keep the step (`Stepper::first_step_after_restart`):
    // the bouncing ball's first step after a bounce must stay Hairer's (a disarmed function)
    fn restart_keeps_step_size(&self) -> bool {
        true
    }
}

/// A named stepper for a toy.
pub(super) type Named<L> = (&'static str, Box<dyn Stepper<Toy<L>>>);

/// Every method, named: rk4 with step `h`, the adaptive ones with `rtol`, `atol`, `h_max`.
pub(super) fn methods<L: Law>(h: f64, rtol: f64, atol: f64, h_max: f64) -> Vec<Named<L>> {
    let c = StepControl { h_max, ..StepControl::new(rtol, atol) };
    vec![
        ("rk4", Box::new(Rk4::new(2, h))),
        ("dopri45", Box::new(DormandPrince45::new(2, c))),
        ("rosenbrock", Box::new(Rosenbrock::new(2, c))),
        ("rodas5p", Box::new(Rodas::new(2, c).with_method(RodasMethod::Rodas5P))),
        ("rodas4", Box::new(Rodas::new(2, c).with_method(RodasMethod::Rodas4))),
        ("imex", Box::new(ArkImex::new(2, c))),
    ]
}

/// A ball dropped from `h0` with `v = 0` under gravity `g`: event `x = 0` downwards, Newton's
/// restitution `v -> -e v`, and the rest rule: an impact slower than `v_rest` is plastic and
/// the ball rests (`v' = 0`, no event) from then on.
pub(super) struct Ball {
    pub(super) g: f64,
    pub(super) e: f64,
    pub(super) v_rest: f64,
    pub(super) resting: bool,
    /// Times of the bounces, and of the rest.
    pub(super) bounces: Vec<f64>,
    pub(super) rest: Option<f64>,
}

impl Ball {
    pub(super) fn new(g: f64, e: f64, v_rest: f64) -> Self {
        Ball { g, e, v_rest, resting: false, bounces: Vec::new(), rest: None }
    }
}

impl Law for Ball {
    fn n(&self) -> usize {
        1
    }
    fn dir(&self, _i: usize) -> i8 {
        -1
    }
    fn acc(&self, _t: f64, _y: &[f64]) -> f64 {
        if self.resting {
            0.0
        } else {
            -self.g
        }
    }
    fn events(&self, _t: f64, y: &[f64], out: &mut [f64]) {
        out[0] = if self.resting { 1.0 } else { y[0] };
    }
    fn handle(&mut self, t: f64, y: &mut [f64], _fired: &[bool]) -> bool {
        if -y[1] < self.v_rest {
            self.resting = true;
            self.rest = Some(t);
            y[0] = 0.0;
            y[1] = 0.0;
        } else {
            self.bounces.push(t);
            y[1] *= -self.e;
        }
        true
    }
}

/// A mass `m` resting on a table (`x = 0`, `v = 0`), pushed up by `F = a t`: in contact the
/// normal force is `f_n = m g − a t` (event, downwards: lift-off), free the mass accelerates by
/// `a t / m − g` (event `x` downwards: touch-down, not reached here).
pub(super) struct LiftOff {
    pub(super) m: f64,
    pub(super) g: f64,
    pub(super) a: f64,
    pub(super) in_contact: bool,
}

impl Law for LiftOff {
    fn n(&self) -> usize {
        1
    }
    fn dir(&self, _i: usize) -> i8 {
        -1
    }
    fn acc(&self, t: f64, _y: &[f64]) -> f64 {
        if self.in_contact {
            0.0
        } else {
            self.a * t / self.m - self.g
        }
    }
    fn events(&self, t: f64, y: &[f64], out: &mut [f64]) {
        out[0] = if self.in_contact { self.m * self.g - self.a * t } else { y[0] };
    }
    fn handle(&mut self, _t: f64, _y: &mut [f64], _fired: &[bool]) -> bool {
        self.in_contact = !self.in_contact;
        false
    }
    /// Its event changes what the function means (force, then height), as the arm's do.
    fn watch(&self) -> Option<f64> {
        Some(0.0)
    }
}

/// A mass resting on a table (`x = 0`, `v = 0`) whose contact force starts at 0, grows and
/// falls back: `f_n = m b t (t_off − t)` (an event downwards, watched: it starts at 0), so
/// it lifts off at `t_off`; free, it is pushed up at `acc_free` (event `x`, downwards).
pub(super) struct Blip {
    pub(super) m: f64,
    pub(super) b: f64,
    pub(super) t_off: f64,
    pub(super) acc_free: f64,
    pub(super) in_contact: bool,
}

impl Law for Blip {
    fn n(&self) -> usize {
        1
    }
    fn dir(&self, _i: usize) -> i8 {
        -1
    }
    fn acc(&self, _t: f64, _y: &[f64]) -> f64 {
        if self.in_contact {
            0.0
        } else {
            self.acc_free
        }
    }
    fn events(&self, t: f64, y: &[f64], out: &mut [f64]) {
        out[0] = if self.in_contact { self.m * self.b * t * (self.t_off - t) } else { y[0] };
    }
    fn handle(&mut self, _t: f64, _y: &mut [f64], _fired: &[bool]) -> bool {
        self.in_contact = !self.in_contact;
        false
    }
    fn watch(&self) -> Option<f64> {
        Some(0.0)
    }
}

/// `x(t) = x0 + t` (`v = 1`) and thresholds: function `i` is `x − c_i` (direction
/// `dirs[i]`); at each event the handler moves the threshold of every fired function to
/// `x + shift` (no move for `shift = None`).
pub(super) struct Thresholds {
    pub(super) c: Vec<f64>,
    pub(super) dirs: Vec<i8>,
    pub(super) shift: Option<f64>,
}

/// [`Thresholds`] whose `init_modes` moves `x0` to `start` (an "impact at t0").
pub(super) struct MovedStart {
    pub(super) inner: Thresholds,
    pub(super) start: f64,
}

impl Law for MovedStart {
    fn n(&self) -> usize {
        self.inner.n()
    }
    fn dir(&self, i: usize) -> i8 {
        self.inner.dir(i)
    }
    fn acc(&self, t: f64, y: &[f64]) -> f64 {
        self.inner.acc(t, y)
    }
    fn events(&self, t: f64, y: &[f64], out: &mut [f64]) {
        self.inner.events(t, y, out)
    }
    fn handle(&mut self, t: f64, y: &mut [f64], fired: &[bool]) -> bool {
        self.inner.handle(t, y, fired)
    }
    fn init(&mut self, y: &mut [f64]) -> bool {
        y[0] = self.start;
        true
    }
}

impl Law for Thresholds {
    fn n(&self) -> usize {
        self.c.len()
    }
    fn dir(&self, i: usize) -> i8 {
        self.dirs[i]
    }
    fn acc(&self, _t: f64, _y: &[f64]) -> f64 {
        0.0
    }
    fn events(&self, _t: f64, y: &[f64], out: &mut [f64]) {
        for (o, c) in out.iter_mut().zip(&self.c) {
            *o = y[0] - c;
        }
    }
    fn handle(&mut self, _t: f64, y: &mut [f64], fired: &[bool]) -> bool {
        if let Some(s) = self.shift {
            for (c, &f) in self.c.iter_mut().zip(fired) {
                if f {
                    *c = y[0] + s;
                }
            }
        }
        false
    }
}
