//! The event driver on abstract hybrid problems with closed-form event times, for every
//! method (`toys.rs`).

use super::toys::{methods, Ball, Blip, LiftOff, Law, MovedStart, Named, Thresholds, Toy};
use super::*;
use crate::integrate::test_problems::{HarmonicOscillator, Kepler, RhsFailure, StiffLinear};
use crate::integrate::{integrate_sampled, ArkImex, DormandPrince45, Rk4, Rodas, Rosenbrock, StepControl};

const G: f64 = 9.81;

/// The samples of a run and its statistics.
type Samples = (Vec<(f64, [f64; 2])>, Stats);

/// Runs `toy` from `y0` at 0 to `t_end`, sampling every `dt`; returns the samples.
fn run<L: Law>(
    st: &mut dyn Stepper<Toy<L>>,
    toy: &mut Toy<L>,
    y0: [f64; 2],
    t_end: f64,
    dt: f64,
    settings: EventSettings,
) -> Result<Samples, IntegrateError<RhsFailure>> {
    let mut samples = Vec::new();
    let stats = integrate_hybrid(st, toy, 0.0, &y0, t_end, dt, None, settings, |t, y, _| {
        samples.push((t, [y[0], y[1]]));
        Ok(())
    })?;
    Ok((samples, stats))
}

/// The ball of [`Ball`] dropped from `h0`: impact times `t_1 = sqrt(2 h0 / g)`,
/// `t_{j+1} = t_j + 2 e u_j / g` with impact speeds `u_1 = g t_1`, `u_{j+1} = e u_j`; the
/// first impact slower than `v_rest` is the rest. Returns (bounce times, rest time).
fn ball_closed_form(h0: f64, e: f64, v_rest: f64) -> (Vec<f64>, f64) {
    let mut t = (2.0 * h0 / G).sqrt();
    let mut u = G * t;
    let mut bounces = Vec::new();
    while u >= v_rest {
        bounces.push(t);
        t += 2.0 * e * u / G;
        u *= e;
    }
    (bounces, t)
}

/// The ball's state at `t` by the closed form (impacts at the closed-form times).
fn ball_state(h0: f64, e: f64, v_rest: f64, t: f64) -> [f64; 2] {
    let (bounces, rest) = ball_closed_form(h0, e, v_rest);
    if t >= rest {
        return [0.0, 0.0];
    }
    // the last impact at or before t, and the upward speed after it
    let (mut t_j, mut v_j, mut x_j) = (0.0, 0.0, h0);
    let mut u = G * (2.0 * h0 / G).sqrt();
    for &tb in &bounces {
        if tb > t {
            break;
        }
        (t_j, v_j, x_j) = (tb, e * u, 0.0);
        u *= e;
    }
    let s = t - t_j;
    [x_j + v_j * s - 0.5 * G * s * s, v_j - G * s]
}

/// Bouncing ball, h0 = 1 m, e = 0.5, v_rest = 1e-3 m/s: u_1 = 4.43 m/s, so 13 bounces (the
/// smallest n with u_1 eⁿ < v_rest is 13) and a rest at the 14th impact. Every method: the
/// impact times within 1e-9 relative of the closed form, the count of bounces exact, the rest
/// time within 1e-9 relative and short of the accumulation time
/// `t_∞ = t_1 + 2 u_1 e / (g (1 − e))` by exactly the closed-form `2 u_14 e / (g (1 − e))`
/// (1e-9 relative); and the samples (both sides of each jump) on the closed form within 1e-9.
/// The solution is piecewise quadratic, which every method (and rk4's cubic Hermite) reproduces,
/// so these bounds test the event location, not the steps.
#[test]
fn bouncing_ball_event_times_match_the_closed_form() {
    let (h0, e, v_rest) = (1.0, 0.5, 1e-3);
    let (bounces, rest) = ball_closed_form(h0, e, v_rest);
    assert_eq!(bounces.len(), 13);
    let t1 = (2.0 * h0 / G).sqrt();
    let u1 = G * t1;
    let n = bounces.len() as i32;
    assert!(u1 * e.powi(n) < v_rest && u1 * e.powi(n - 1) >= v_rest);
    let t_inf = t1 + 2.0 * u1 * e / (G * (1.0 - e));
    // rk4's step (1e-5 s) is shorter than the shortest flight (1.1e-4 s): a flight within
    // one fixed step is not seen (module doc)
    for (name, mut st) in methods::<Ball>(1e-5, 1e-10, 1e-12, 0.05) {
        let mut toy = Toy::new(Ball::new(G, e, v_rest));
        let (samples, stats) = run(st.as_mut(), &mut toy, [h0, 0.0], 2.0, 1e-3, EventSettings::default()).expect(name);
        let ball = &toy.law;
        assert_eq!(ball.bounces.len(), bounces.len(), "{name}: bounces");
        for (j, (t, t_cf)) in ball.bounces.iter().zip(&bounces).enumerate() {
            assert!(((t - t_cf) / t_cf).abs() <= 1e-9, "{name}: bounce {j} at {t}, closed form {t_cf}");
        }
        let t_rest = ball.rest.expect("rests");
        assert!(((t_rest - rest) / rest).abs() <= 1e-9, "{name}: rest at {t_rest}, closed form {rest}");
        let short = 2.0 * u1 * e.powi(n) * e / (G * (1.0 - e));
        assert!(((t_inf - t_rest) - short).abs() <= 1e-9 * t_inf, "{name}: t_inf - t_rest = {}, closed form {short}", t_inf - t_rest);
        assert_eq!(samples.len(), 2001, "{name}");
        let mut worst: f64 = 0.0;
        for (t, y) in &samples {
            let ex = ball_state(h0, e, v_rest, *t);
            worst = worst.max((y[0] - ex[0]).abs()).max((y[1] - ex[1]).abs());
        }
        assert!(worst <= 1e-9, "{name}: samples off the closed form by {worst:e}");
        eprintln!(
            "{name}: {} events, {} rhs in steps ({} steps), {} event-function evaluations ({:.1} per located event beyond the 2 per step)",
            toy.log.len(),
            stats.rhs_evals,
            stats.steps,
            toy.event_calls,
            (toy.event_calls as f64 - 2.0 * stats.steps as f64) / toy.log.len() as f64,
        );
    }
}

/// Without a rest rule (v_rest = 0) the bounces accumulate at t_∞ (Zeno). What the driver
/// does then, stated: it follows the bounces (closed-form times to 1e-9 relative) until a
/// flight is shorter than what it can resolve (the restart's first step, or the chattering
/// window); then either the chattering guard stops the run, or the ball, restarted just below
/// the table (t* is the bracket's upper end), passes it unseen. Either way the last event is
/// at t_∞ within 1e-9 s — which is why rigid contacts need the rest rule.
#[test]
fn zeno_without_rest_rule_is_followed_to_the_accumulation_time() {
    let (h0, e) = (1.0, 0.5);
    let t1 = (2.0 * h0 / G).sqrt();
    let t_inf = t1 + 2.0 * G * t1 * e / (G * (1.0 - e));
    for (name, mut st) in methods::<Ball>(1e-3, 1e-10, 1e-12, 0.05).into_iter().skip(1) {
        let mut toy = Toy::new(Ball::new(G, e, 0.0));
        let res = run(st.as_mut(), &mut toy, [h0, 0.0], 2.0, 1e-3, EventSettings::default());
        let times = toy.times();
        let (bounces, _) = ball_closed_form(h0, e, 1e-6);
        for (j, (t, t_cf)) in times.iter().zip(&bounces).enumerate() {
            assert!(((t - t_cf) / t_cf).abs() <= 1e-9, "{name}: bounce {j} at {t}, closed form {t_cf}");
        }
        let last = times.last().copied().unwrap_or(0.0);
        assert!(times.len() >= bounces.len(), "{name}: only {} bounces", times.len());
        assert!((last - t_inf).abs() <= 1e-9, "{name}: last event at {last}, t_inf = {t_inf}");
        let how = match res {
            Err(IntegrateError::Chattering { .. }) => "chattering guard".to_string(),
            Ok(_) => "ball passed the table".to_string(),
            other => panic!("{name}: {:?}", other.map(|r| r.1)),
        };
        eprintln!("{name}: {} events, last at t_inf - {:.2e} s, then {how}", times.len(), t_inf - last);
    }
}

/// g(t) = x(t) − 0.3 with x = t (direction +1): located to 1e-12 s (the methods' x is t up
/// to round-off, ~1e-15), by every method, with steps far larger than the tolerance.
#[test]
fn a_time_linear_event_is_located_to_the_time_tolerance() {
    for (name, mut st) in methods::<Thresholds>(0.1, 1e-8, 1e-10, 0.25) {
        let mut toy = Toy::new(Thresholds { c: vec![0.3], dirs: vec![1], shift: None });
        run(st.as_mut(), &mut toy, [0.0, 1.0], 1.0, 0.1, EventSettings::default()).expect(name);
        let t = toy.times();
        assert_eq!(t.len(), 1, "{name}: {t:?}");
        assert!((t[0] - 0.3).abs() <= 1e-12, "{name}: t* - 0.3 = {:e}", t[0] - 0.3);
    }
}

/// The mass on the table pushed by F = a t (m = 2 kg, a = 7 N/s): lift-off at t_L = m g / a
/// within 1e-10 s; afterwards x(t) = a (t − t_L)³ / (6 m) (samples within 1e-9 m).
#[test]
fn lift_off_under_a_linear_force_at_the_closed_form_time() {
    let (m, a) = (2.0, 7.0);
    let t_l = m * G / a;
    for (name, mut st) in methods::<LiftOff>(1e-2, 1e-10, 1e-12, 0.05) {
        let mut toy = Toy::new(LiftOff { m, g: G, a, in_contact: true });
        let (samples, _) = run(st.as_mut(), &mut toy, [0.0, 0.0], 3.5, 0.01, EventSettings::default()).expect(name);
        let t = toy.times();
        assert_eq!(t.len(), 1, "{name}: {t:?}");
        assert!((t[0] - t_l).abs() <= 1e-10, "{name}: lift-off at {}, closed form {t_l}", t[0]);
        for (t, y) in &samples {
            let x = if *t < t_l { 0.0 } else { a * (t - t_l).powi(3) / (6.0 * m) };
            assert!((y[0] - x).abs() <= 1e-9, "{name}: x({t}) = {}, closed form {x}", y[0]);
        }
    }
}

/// A function that starts on its firing side is watched from its start value (module doc): the
/// mass on the table with no weight (m g = 0, so the contact force is exactly 0 at t0) pushed by
/// F = a t would be held by a pulling table (force −a t) if the zero start disarmed the lift-off;
/// it lifts off at t0 itself, then x(t) = a t³ / (6 m) (within 1e-9 m), for every method.
#[test]
fn a_contact_force_that_starts_at_zero_and_turns_negative_lifts_off_at_once() {
    let (m, a) = (2.0, 7.0);
    for (name, mut st) in methods::<LiftOff>(1e-2, 1e-10, 1e-12, 0.05) {
        let mut toy = Toy::new(LiftOff { m, g: 0.0, a, in_contact: true });
        let (samples, _) = run(st.as_mut(), &mut toy, [0.0, 0.0], 1.0, 0.01, EventSettings::default()).expect(name);
        let t = toy.times();
        assert_eq!(t, vec![0.0], "{name}: one lift-off, at t0");
        for (t, y) in &samples {
            let x = a * t.powi(3) / (6.0 * m);
            assert!((y[0] - x).abs() <= 1e-9, "{name}: x({t}) = {}, closed form {x}", y[0]);
        }
    }
}

/// A watched function that leaves its start value the other way and comes back past it within
/// one step has its root inside the step, not at the step's start: the contact force
/// `f_n = m b t (t_off − t)` starts at 0, is positive until `t_off` = 3e-3 s (inside rk4's
/// first step of 1e-2 s, and inside the adaptive methods' first step of a constant state),
/// then negative; the mass lifts off at `t_off` (to 1e-12 s), then x(t) = a (t − t_off)² / 2
/// (1e-9 m), for every method. Taken as moving straight to its firing side, it lifted off at
/// t0 (the arm's gear that starts sliding from rest and stops within one step, issue 26).
#[test]
fn a_function_that_departs_and_returns_within_a_step_fires_at_its_return() {
    let (t_off, a) = (3e-3, 2.0);
    for (name, mut st) in methods::<Blip>(1e-2, 1e-10, 1e-12, 0.05) {
        let mut toy = Toy::new(Blip { m: 2.0, b: 50.0, t_off, acc_free: a, in_contact: true });
        let (samples, _) = run(st.as_mut(), &mut toy, [0.0, 0.0], 0.1, 0.01, EventSettings::default()).expect(name);
        let t = toy.times();
        assert_eq!(t.len(), 1, "{name}: one lift-off, {t:?}");
        assert!((t[0] - t_off).abs() <= 1e-12, "{name}: lift-off at {}, closed form {t_off}", t[0]);
        for (t, y) in &samples {
            let x = if *t > t_off { a * (t - t_off).powi(2) / 2.0 } else { 0.0 };
            assert!((y[0] - x).abs() <= 1e-9, "{name}: x({t}) = {}, closed form {x}", y[0]);
        }
    }
}

/// Two thresholds crossed in the same step (0.41 and 0.40, rk4 step 1 and an adaptive h_max
/// of 1): the earlier (function 1, at 0.40) is handled first, alone, then function 0 at 0.41;
/// a function exactly 0 at the start (x − 0, direction 0) is never reported.
#[test]
fn the_earlier_of_two_events_in_one_step_is_handled_first() {
    for (name, mut st) in methods::<Thresholds>(1.0, 1e-6, 1e-9, 1.0) {
        let mut toy = Toy::new(Thresholds { c: vec![0.41, 0.40, 0.0], dirs: vec![1, 1, 0], shift: None });
        run(st.as_mut(), &mut toy, [0.0, 1.0], 1.0, 0.5, EventSettings::default()).expect(name);
        let fired: Vec<(f64, Vec<bool>)> = toy.log.iter().map(|(t, f, _)| (*t, f.clone())).collect();
        assert_eq!(fired.len(), 2, "{name}: {fired:?}");
        assert_eq!(fired[0].1, vec![false, true, false], "{name}");
        assert_eq!(fired[1].1, vec![true, false, false], "{name}");
        assert!((fired[0].0 - 0.40).abs() <= 1e-12 && (fired[1].0 - 0.41).abs() <= 1e-12, "{name}: {fired:?}");
    }
}

/// Two functions with the same root fire together, in one event.
#[test]
fn simultaneous_roots_fire_together() {
    for (name, mut st) in methods::<Thresholds>(0.1, 1e-8, 1e-10, 0.25) {
        let mut toy = Toy::new(Thresholds { c: vec![0.5, 0.5], dirs: vec![1, 0], shift: None });
        run(st.as_mut(), &mut toy, [0.0, 1.0], 1.0, 0.5, EventSettings::default()).expect(name);
        assert_eq!(toy.log.len(), 1, "{name}");
        assert_eq!(toy.log[0].1, vec![true, true], "{name}");
    }
}

/// A handler that moves the threshold 1e-13 s ahead at every event keeps firing at (almost)
/// the same time: after 32 such events in a row the run stops with Chattering (count 33, at
/// t ≈ 0.5); one that moves it 0.01 s ahead fires every 0.01 s and, with max_events = 5,
/// stops with TooManyEvents at the 6th event (t ≈ 0.55).
#[test]
fn chattering_and_max_events_are_typed_errors() {
    for (name, mut st) in methods::<Thresholds>(0.1, 1e-8, 1e-10, 0.25) {
        let mut toy = Toy::new(Thresholds { c: vec![0.5], dirs: vec![1], shift: Some(1e-13) });
        match run(st.as_mut(), &mut toy, [0.0, 1.0], 1.0, 0.1, EventSettings::default()) {
            Err(IntegrateError::Chattering { t, count, window, events }) => {
                assert_eq!(count, 33, "{name}");
                assert!((t - 0.5).abs() < 1e-10 && window == 1e-11 && events.contains("[0]"), "{name}: {t} {window} {events}");
            }
            other => panic!("{name}: expected Chattering, got {:?}", other.map(|r| r.1)),
        }
        // the limit is a setting (the scene's events.max_events_at_one_time): 64 stops at 65
        let mut toy = Toy::new(Thresholds { c: vec![0.5], dirs: vec![1], shift: Some(1e-13) });
        let mut st = methods::<Thresholds>(0.1, 1e-8, 1e-10, 0.25).into_iter().find(|m| m.0 == name).unwrap().1;
        let settings = EventSettings { max_events_at_one_time: 64, ..EventSettings::default() };
        match run(st.as_mut(), &mut toy, [0.0, 1.0], 1.0, 0.1, settings) {
            Err(IntegrateError::Chattering { count: 65, .. }) => assert_eq!(toy.log.len(), 64, "{name}"),
            other => panic!("{name}: expected Chattering after 65, got {:?}", other.map(|r| r.1)),
        }
    }
    for (name, mut st) in methods::<Thresholds>(0.1, 1e-8, 1e-10, 0.25) {
        let mut toy = Toy::new(Thresholds { c: vec![0.5], dirs: vec![1], shift: Some(0.01) });
        let settings = EventSettings { max_events: 5, ..EventSettings::default() };
        match run(st.as_mut(), &mut toy, [0.0, 1.0], 1.0, 0.1, settings) {
            Err(IntegrateError::TooManyEvents { t, max_events: 5 }) => {
                assert!((t - 0.55).abs() < 1e-9, "{name}: {t}");
                assert_eq!(toy.log.len(), 5, "{name}");
            }
            other => panic!("{name}: expected TooManyEvents, got {:?}", other.map(|r| r.1)),
        }
    }
}

/// Statistics are summed over restarts: a run with events reports at least the steps of its
/// last segment plus one per event-free segment, and after_step is called once per accepted
/// step without an event.
#[test]
fn statistics_accumulate_over_restarts() {
    let mut st = DormandPrince45::new(2, StepControl { h_max: 0.05, ..StepControl::new(1e-10, 1e-12) });
    let mut toy = Toy::new(Ball::new(G, 0.5, 1e-3));
    let (_, stats) = run(&mut st, &mut toy, [1.0, 0.0], 2.0, 1e-3, EventSettings::default()).unwrap();
    let n_ev = toy.log.len() as u64;
    assert_eq!(n_ev, 14);
    assert!(stats.steps > st.stats().steps + n_ev, "{stats:?} vs last segment {:?}", st.stats());
    assert_eq!(toy.after_steps, stats.steps - n_ev - 1, "the last step ends the run, each event's step has none");
    assert!(stats.rhs_evals >= 6 * stats.steps);
}

/// The test problems as hybrid systems without events.
impl HybridSystem for crate::integrate::testutil::Problem {
    fn n_events(&self) -> usize {
        0
    }
    fn event_direction(&self, _i: usize) -> i8 {
        0
    }
    fn events(&mut self, _t: f64, _y: &[f64], _out: &mut [f64]) -> Result<(), RhsFailure> {
        Ok(())
    }
    fn init_modes(&mut self, _t: f64, _y: &mut [f64]) -> Result<bool, RhsFailure> {
        Ok(false)
    }
    fn handle_events(&mut self, _t: f64, _y: &mut [f64], _fired: &[bool]) -> Result<bool, RhsFailure> {
        Ok(false)
    }
}

/// With no event functions, integrate_hybrid is integrate_sampled: the same samples bit for
/// bit and the same statistics, for every method, on a non-stiff and a stiff problem.
#[test]
fn without_events_the_samples_are_integrate_sampled_bit_for_bit() {
    use crate::integrate::testutil::Problem;
    let c = StepControl::new(1e-7, 1e-9);
    let build = |name: &str, dim: usize| -> Box<dyn Stepper<Problem>> {
        match name {
            "rk4" => Box::new(Rk4::new(dim, 0.013)),
            "dopri45" => Box::new(DormandPrince45::new(dim, c)),
            "rosenbrock" => Box::new(Rosenbrock::new(dim, c)),
            "rodas5p" => Box::new(Rodas::new(dim, c)),
            "imex" => Box::new(ArkImex::new(dim, c)),
            _ => unreachable!(),
        }
    };
    for problem in [Problem::Kepler(Kepler { e: 0.5 }), Problem::Oscillator(HarmonicOscillator::default()), Problem::Pr(StiffLinear::default())] {
        let stiff = matches!(problem, Problem::Pr(_));
        for name in ["rk4", "dopri45", "rosenbrock", "rodas5p", "imex"] {
            if stiff && (name == "rk4" || name == "dopri45") {
                continue; // explicit methods on λ = -1e4: unstable / stopped as stiff
            }
            let mut p = problem;
            let dim = p.dim();
            let y0 = crate::integrate::test_problems::ExactSolution::y0(&p);
            let mut a = Vec::new();
            let sa = integrate_sampled(build(name, dim).as_mut(), &mut p, 0.0, &y0, 2.0, 0.03, |t, y| {
                a.push((t, y.to_vec()));
                Ok(())
            })
            .unwrap();
            let mut p = problem;
            let mut b = Vec::new();
            let sb = integrate_hybrid(build(name, dim).as_mut(), &mut p, 0.0, &y0, 2.0, 0.03, None, EventSettings::default(), |t, y, _| {
                b.push((t, y.to_vec()));
                Ok(())
            })
            .unwrap();
            assert_eq!(sa, sb, "{name}");
            assert_eq!(a.len(), b.len(), "{name}");
            for ((ta, ya), (tb, yb)) in a.iter().zip(&b) {
                assert_eq!(ta.to_bits(), tb.to_bits(), "{name}");
                assert!(ya.iter().zip(yb).all(|(x, y)| x.to_bits() == y.to_bits()), "{name} at {ta}: {ya:?} vs {yb:?}");
            }
        }
    }
}

#[test]
fn time_tolerance_is_the_setting_or_4_ulp() {
    assert_eq!(time_tolerance(1e-12, 1.0), 1e-12);
    assert_eq!(time_tolerance(1e-12, 1e6), 4.0 * (f64::from_bits(1e6f64.to_bits() + 1) - 1e6));
    assert_eq!(time_tolerance(0.0, 1.0), 4.0 * f64::EPSILON);
    assert_eq!(time_tolerance(f64::NAN, 1.0), 4.0 * f64::EPSILON);
}

/// `Integrator::integrate_hybrid` (the scene's integrator) drives the event driver with every
/// method of a scene: the bouncing ball's impact times within 1e-9 relative of the closed
/// form, 13 bounces and a rest, through the scene-level dispatch.
#[test]
fn the_scene_integrator_dispatches_every_method_to_the_event_driver() {
    use crate::integrator::Integrator;
    let (h0, e, v_rest) = (1.0, 0.5, 1e-3);
    let (bounces, rest) = ball_closed_form(h0, e, v_rest);
    for json in [
        r#"{"method":"rk4","step":1e-5}"#,
        r#"{"method":"dopri45","rtol":1e-10,"atol":1e-12,"h_max":0.05}"#,
        r#"{"method":"rosenbrock","rtol":1e-10,"atol":1e-12,"h_max":0.05}"#,
        r#"{"method":"rodas5p","rtol":1e-10,"atol":1e-12,"h_max":0.05}"#,
        r#"{"method":"rodas4","rtol":1e-10,"atol":1e-12,"h_max":0.05}"#,
        r#"{"method":"imex","rtol":1e-10,"atol":1e-12,"h_max":0.05}"#,
    ] {
        let spec = serde_json::from_str(json).unwrap();
        let integrator = Integrator::from_spec(&spec, "ball.json", 2.0, 1e-3).unwrap();
        let mut toy = Toy::new(Ball::new(G, e, v_rest));
        let mut n = 0;
        let stats = integrator
            .integrate_hybrid(&mut toy, &[h0, 0.0], 2.0, 1e-3, None, EventSettings::default(), |_, _, _| {
                n += 1;
                Ok(())
            })
            .expect(json);
        assert_eq!(n, 2001, "{json}");
        assert!(stats.steps > 0);
        assert_eq!(toy.law.bounces.len(), bounces.len(), "{json}");
        for (t, t_cf) in toy.law.bounces.iter().zip(&bounces) {
            assert!(((t - t_cf) / t_cf).abs() <= 1e-9, "{json}: {t} vs {t_cf}");
        }
        let t_rest = toy.law.rest.expect("rests");
        assert!(((t_rest - rest) / rest).abs() <= 1e-9, "{json}: rest {t_rest} vs {rest}");
    }
}

/// A handler that leaves its function exactly 0 at the restart (threshold moved onto the
/// state, direction 0) does not fire again at once: the function is disarmed until it has
/// left 0, then it only grows. One event, no chattering, for every method.
#[test]
fn a_function_left_at_zero_by_the_handler_is_disarmed() {
    for (name, mut st) in methods::<Thresholds>(0.1, 1e-8, 1e-10, 0.25) {
        let mut toy = Toy::new(Thresholds { c: vec![0.5], dirs: vec![0], shift: Some(0.0) });
        run(st.as_mut(), &mut toy, [0.0, 1.0], 1.0, 0.1, EventSettings::default()).expect(name);
        assert_eq!(toy.log.len(), 1, "{name}: {:?}", toy.times());
    }
}

/// init_modes runs before the first sample: a start it moves (x0 = 0 -> 0.2) is the first
/// sample, and the threshold at 0.5 is then crossed at t = 0.3 (1e-12 s); without a move the
/// first sample is y0 bit for bit.
#[test]
fn init_modes_runs_before_the_first_sample() {
    for (name, mut st) in methods::<MovedStart>(0.1, 1e-8, 1e-10, 0.25) {
        let mut toy = Toy::new(MovedStart { inner: Thresholds { c: vec![0.5], dirs: vec![1], shift: None }, start: 0.2 });
        let (samples, _) = run(st.as_mut(), &mut toy, [0.0, 1.0], 1.0, 0.1, EventSettings::default()).expect(name);
        assert_eq!(samples[0], (0.0, [0.2, 1.0]), "{name}");
        assert!((toy.times()[0] - 0.3).abs() <= 1e-12, "{name}: {:?}", toy.times());
    }
    let y0 = [0.1 + 0.2, 1.0 / 3.0];
    let mut toy = Toy::new(Thresholds { c: vec![5.0], dirs: vec![1], shift: None });
    let (samples, _) = run(&mut Rk4::new(2, 0.1), &mut toy, y0, 1.0, 0.1, EventSettings::default()).unwrap();
    assert_eq!(samples[0].1.map(f64::to_bits), y0.map(f64::to_bits));
}

/// The budget is read inside the event location too (issue 29): with the deadline already
/// past, a step that crosses the ball's impact stops at the location's first trial point, as
/// [`IntegrateError::OutOfTime`] at the step's start with where it was, instead of locating the
/// root (some 40 evaluations of every event function, each a right-hand side for the arm)
/// and handling the event first. One rk4 step of 1 s crosses the impact at 0.45 s; the
/// driver's own clock, read every 16 steps, has not looked yet.
#[test]
fn the_deadline_stops_an_event_location() {
    let mut toy = Toy::new(Ball::new(G, 0.5, 1e-3));
    let mut st = Rk4::new(2, 1.0);
    let deadline = Some(Deadline::new(std::time::Instant::now()));
    let r = integrate_hybrid(&mut st, &mut toy, 0.0, &[1.0, 0.0], 1.0, 0.5, deadline, EventSettings::default(), |_, _, _| Ok(()));
    match r {
        Err(IntegrateError::OutOfTime { t, during }) => {
            assert_eq!((t, during), (0.0, crate::integrate::Phase::LocatingEvent { trials: 0 }));
        }
        other => panic!("expected OutOfTime while locating, got {other:?}"),
    }
    // the functions at the start and at the step's end, no trial point, no event handled
    assert_eq!((toy.event_calls, toy.log.len()), (2, 0));
}

/// Two functions of a point `x = t²/2` (from rest, `x'' = 1`), both direction −1 and watched:
/// `g₀ = −ε x`, 0 at the start (on its firing side, so watched from 0, dead band `tol`), past
/// `−tol` only from `t_w = √(2 tol / ε)`; `g₁ = c − x`, a threshold at `t_r = √(2 c)` < `t_w`.
/// The first step spans both (rk4's step, and the adaptive methods' first step of 1, exact
/// for a quadratic). `g₀` still within its dead band at `t_r` cannot have fired before `g₁`:
/// the first event is `g₁` alone at `t_r` (to 1e-12 s). The driver fired `g₀` at the step's
/// start before (`Bracket::hold_start_firing`; the arm's elbow whose touch-down pre-empted
/// the other elbow's landing, `touchdown-refire-pair.json`).
struct DeadBandAndThreshold {
    eps: f64,
    c: f64,
    tol: f64,
    reached: [bool; 2],
}

impl Law for DeadBandAndThreshold {
    fn n(&self) -> usize {
        2
    }
    fn dir(&self, _i: usize) -> i8 {
        -1
    }
    fn acc(&self, _t: f64, _y: &[f64]) -> f64 {
        1.0
    }
    fn events(&self, _t: f64, y: &[f64], out: &mut [f64]) {
        // a function that has fired is done (its mode switched): positive from then on
        out[0] = if self.reached[0] { 1.0 } else { -self.eps * y[0] };
        out[1] = if self.reached[1] { 1.0 } else { self.c - y[0] };
    }
    fn handle(&mut self, _t: f64, _y: &mut [f64], fired: &[bool]) -> bool {
        self.reached[0] |= fired[0];
        self.reached[1] |= fired[1];
        false
    }
    fn watch(&self) -> Option<f64> {
        Some(self.tol)
    }
}

#[test]
fn a_function_within_its_dead_band_does_not_pre_empt_another_root_in_the_step() {
    let (eps, c, tol): (f64, f64, f64) = (2e-8, 0.02, 1e-9);
    let t_r = (2.0 * c).sqrt();
    assert!(t_r < (2.0 * tol / eps).sqrt());
    let ctl = StepControl { h_max: 1.0, h_init: Some(1.0), ..StepControl::new(1e-8, 1e-10) };
    let steppers: Vec<Named<DeadBandAndThreshold>> = vec![
        ("rk4", Box::new(Rk4::new(2, 1.0))),
        ("dopri45", Box::new(DormandPrince45::new(2, ctl))),
        ("rodas5p", Box::new(Rodas::new(2, ctl))),
    ];
    for (name, mut st) in steppers {
        let mut toy = Toy::new(DeadBandAndThreshold { eps, c, tol, reached: [false; 2] });
        run(st.as_mut(), &mut toy, [0.0, 0.0], 1.0, 1.0, EventSettings::default()).expect(name);
        let (t, fired, _) = &toy.log[0];
        assert_eq!(fired, &vec![false, true], "{name}: first event {:?}", toy.log);
        assert!((t - t_r).abs() <= 1e-12, "{name}: first event at {t}, closed form {t_r}");
    }
}

/// A gap that starts at 0 (watched from there, dead band `tol`) and rises less than the dead
/// band before it comes back through: `x'' = a − b t` from rest, `x = a t²/2 − b t³/6`, its
/// top `a³/(3 b²)` at `a/b` and its return to 0 at `t* = 3 a/b`; one step of 0.01 s (rk4's;
/// the adaptive methods' first step, exact for this cubic) ends at `x = −1.2e-7` < `−tol`.
/// With a departure bound below the top (`event_departure`, 1e-12 against the top 3.3e-10 and
/// `tol` 1e-9) the probe at h/4 (`x` = 5.2e-10) is a departure and the return is located at
/// `t*` (to 1e-12 s); with the bound at the dead band (the default) the function fires at the
/// step's start, t = 0, where a contact's handler finds it leaving again and the same step is
/// retaken (issue 23 item 6 A, `touchdown-refire-pair-tight.json`).
struct RiseBelowTheDeadBand {
    a: f64,
    b: f64,
    tol: f64,
    departure: Option<f64>,
    reached: bool,
}

impl Law for RiseBelowTheDeadBand {
    fn n(&self) -> usize {
        1
    }
    fn dir(&self, _i: usize) -> i8 {
        -1
    }
    fn acc(&self, t: f64, _y: &[f64]) -> f64 {
        self.a - self.b * t
    }
    fn events(&self, _t: f64, y: &[f64], out: &mut [f64]) {
        out[0] = if self.reached { 1.0 } else { y[0] };
    }
    fn handle(&mut self, _t: f64, _y: &mut [f64], fired: &[bool]) -> bool {
        self.reached |= fired[0];
        false
    }
    fn watch(&self) -> Option<f64> {
        Some(self.tol)
    }
    fn departure(&self) -> Option<f64> {
        self.departure.or(Some(self.tol))
    }
}

#[test]
fn a_rise_below_the_dead_band_and_back_is_located_with_a_finer_departure_bound() {
    let (a, b, tol, h): (f64, f64, f64, f64) = (1e-3, 1.0, 1e-9, 0.01);
    let t_star = 3.0 * a / b;
    let top = a.powi(3) / (3.0 * b * b);
    assert!(top > 1e-12 && top < tol && a * h * h / 2.0 - b * h.powi(3) / 6.0 < -tol);
    let ctl = StepControl { h_max: h, h_init: Some(h), ..StepControl::new(1e-8, 1e-10) };
    for (departure, want) in [(Some(1e-12), t_star), (None, 0.0)] {
        let steppers: Vec<Named<RiseBelowTheDeadBand>> = vec![
            ("rk4", Box::new(Rk4::new(2, h))),
            ("dopri45", Box::new(DormandPrince45::new(2, ctl))),
            ("rodas5p", Box::new(Rodas::new(2, ctl))),
        ];
        for (name, mut st) in steppers {
            let mut toy = Toy::new(RiseBelowTheDeadBand { a, b, tol, departure, reached: false });
            run(st.as_mut(), &mut toy, [0.0, 0.0], 2.0 * h, h, EventSettings::default()).expect(name);
            let (t, fired, _) = &toy.log[0];
            assert_eq!(fired, &vec![true], "{name}: {:?}", toy.log);
            assert!((t - want).abs() <= 1e-12, "{name}, departure {departure:?}: the event at {t} s, want {want} s");
        }
    }
}
