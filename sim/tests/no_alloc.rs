//! No heap allocation in the step loop: a counting global allocator (per thread) around the
//! integration of the paper's two-elbow run (the RHS: IK, PD, RNEA, CRBA, contacts, Cholesky
//! and Schur complement), for every integrator, after construction and the first step, over
//! 1100 steps (dopri45's stiffness test runs at step 1000); and the driver with its wall-clock
//! deadline allocates the same for 100 steps as for 500; so does the event driver
//! (`integrate_hybrid`) for a bouncing ball, whatever its step count.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

use std::time::{Duration, Instant};

use sim::integrate::{integrate_hybrid, integrate_sampled_within, ArkImex, EventSettings, HybridSystem, OdeSystem, Deadline, DormandPrince45, Rk4, Rodas, RodasMethod, Rosenbrock, StepControl, Stepper};
use sim::scene::Scene;
use sim::ode::ArmSystem;

struct Counting;

thread_local! {
    static ALLOCS: Cell<u64> = const { Cell::new(0) };
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let _ = ALLOCS.try_with(|c| c.set(c.get() + 1));
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let _ = ALLOCS.try_with(|c| c.set(c.get() + 1));
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

fn allocs() -> u64 {
    ALLOCS.with(Cell::get)
}

fn steps_allocate<'s, St: Stepper<ArmSystem<'s>>>(st: &mut St, sys: &mut ArmSystem<'s>) -> u64 {
    let y0 = sys.initial_state();
    let mut out = vec![0.0; y0.len()];
    st.init(sys, 0.0, &y0).expect("init");
    st.step(sys, 2.0).expect("first step");
    let before = allocs();
    // past step 1000, where dopri45's stiffness test runs
    for _ in 0..1100 {
        let t = st.step(sys, 2.0).expect("step");
        st.interpolate(t, &mut out);
    }
    allocs() - before
}

#[test]
fn the_step_loop_does_not_allocate() {
    let scene = Scene::paper().unwrap();
    let run = scene.run("two-elbow").unwrap().clone();
    let mut sys = ArmSystem::new(&scene, &run);
    let dim = sys.initial_state().len();
    assert_eq!(steps_allocate(&mut Rk4::new(dim, 1e-4), &mut sys), 0, "rk4");
    let control = |rtol, atol| StepControl { h_max: 1e-3, max_steps: 100_000, ..StepControl::new(rtol, atol) };
    assert_eq!(steps_allocate(&mut DormandPrince45::new(dim, control(1e-10, 1e-12)), &mut sys), 0, "dopri45");
    let st = &mut Rosenbrock::new(dim, control(1e-8, 1e-10));
    assert_eq!(steps_allocate(st, &mut sys), 0, "rosenbrock (with its Jacobian)");
    assert_eq!(steps_allocate(&mut ArkImex::new(dim, control(1e-8, 1e-10)), &mut sys), 0, "imex");
    let st = &mut Rodas::new(dim, control(1e-8, 1e-10));
    assert_eq!(steps_allocate(st, &mut sys), 0, "rodas5p (with its finite-difference Jacobian)");
    let st = &mut Rodas::new(dim, control(1e-8, 1e-10)).with_method(RodasMethod::Rodas4);
    assert_eq!(steps_allocate(st, &mut sys), 0, "rodas4");
}

/// Projection after every step (the constraint stabilisation) does not allocate either.
#[test]
fn projection_does_not_allocate() {
    let scene = Scene::paper().unwrap().vary(|s| s.dynamics.stabilization = sim::dynamics::forward::Stabilization::Projection).unwrap();
    let run = scene.run("two-elbow").unwrap().clone();
    let mut sys = ArmSystem::new(&scene, &run);
    let mut y = sys.initial_state();
    y[0] += 1e-3;
    y[2] += 1e-3;
    sys.project_onto_constraints(0.0, &mut y).unwrap();
    let before = allocs();
    y[1] += 1e-4;
    y[12] += 1e-4;
    assert!(sys.project_onto_constraints(0.1, &mut y).unwrap());
    assert_eq!(allocs() - before, 0);
}

/// The driver with a wall-clock deadline (read every few steps) allocates only its buffer,
/// however many steps it takes.
#[test]
fn the_driver_with_a_deadline_does_not_allocate_per_step() {
    let scene = Scene::paper().unwrap();
    let run = scene.run("two-elbow").unwrap().clone();
    let mut sys = ArmSystem::new(&scene, &run);
    let y0 = sys.initial_state();
    let mut count = |t_end: f64| {
        let mut st = Rk4::new(y0.len(), 1e-4);
        let deadline = Some(Deadline::new(Instant::now() + Duration::from_secs(3600)));
        let before = allocs();
        integrate_sampled_within(&mut st, &mut sys, 0.0, &y0, t_end, 1e-3, deadline, |_, _| Ok(())).unwrap();
        allocs() - before
    };
    let (short, long) = (count(0.01), count(0.05));
    assert_eq!(short, long, "100 steps: {short} allocations, 500 steps: {long}");
}

/// The real drives (K_e, voltage and current limits), the soft joint stops and the controller
/// laws (PD + gravity with friction, computed torque with its current loop) allocate nothing
/// in the step loop either, for an explicit, a Rosenbrock-W (structured Jacobian) and a
/// classical Rosenbrock method.
#[test]
fn the_drives_and_controllers_do_not_allocate() {
    use sim::scene::spec::{JointLimitsSpec, LawSpec, PerJoint, PositionLimitMode};
    let drives = |s: &mut sim::scene::SceneSpec| {
        s.motor.back_emf_constant = Some(PerJoint::All(0.21));
        s.motor.voltage_limit = Some(PerJoint::All(24.0));
        s.motor.current_limit = Some(PerJoint::All(10.0));
        s.joint_limits = Some(JointLimitsSpec { position: PositionLimitMode::Stop, stiffness: Some(1e3), damping: Some(1.0) });
    };
    let pdg = Scene::paper().unwrap().vary(|s| {
        drives(s);
        s.controller.law = Some(LawSpec::PdGravity);
        s.controller.friction = Some(true);
    });
    let ct = Scene::paper().unwrap().vary(|s| {
        drives(s);
        s.controller.law = Some(LawSpec::ComputedTorque);
        s.controller.kp = PerJoint::All(400.0);
        s.controller.kd = PerJoint::All(40.0);
        s.controller.current_gain = Some(PerJoint::All(5.0));
    });
    for scene in [pdg.unwrap(), ct.unwrap()] {
        let run = scene.run("two-elbow").unwrap().clone();
        let mut sys = ArmSystem::new(&scene, &run);
        let dim = sys.initial_state().len();
        let control = |rtol, atol| StepControl { h_max: 1e-3, max_steps: 100_000, ..StepControl::new(rtol, atol) };
        let law = scene.controller().law.name();
        assert_eq!(steps_allocate(&mut DormandPrince45::new(dim, control(1e-10, 1e-12)), &mut sys), 0, "{law}: dopri45");
        assert_eq!(steps_allocate(&mut Rosenbrock::new(dim, control(1e-8, 1e-10)), &mut sys), 0, "{law}: rosenbrock");
        assert_eq!(steps_allocate(&mut Rodas::new(dim, control(1e-8, 1e-10)), &mut sys), 0, "{law}: rodas5p");
    }
}

/// The targets of issue 10 (joint-space quintics; a Cartesian path tracked by the general IK,
/// evaluated through its joint-space spline) do not allocate in the step loop either, nor does
/// the recorded desired hand (FK of q_d for a joint target) or q̈_d of the paper target.
#[test]
fn targets_do_not_allocate() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/targets");
    for name in ["joint-spline", "square-lines", "tilted-circle"] {
        let scene = Scene::load(&dir.join(format!("{name}.json"))).unwrap();
        let run = scene.run("two-elbow").unwrap().clone();
        let mut sys = ArmSystem::new(&scene, &run);
        let dim = sys.initial_state().len();
        let control = StepControl { h_max: 1e-3, max_steps: 100_000, ..StepControl::new(1e-8, 1e-10) };
        assert_eq!(steps_allocate(&mut DormandPrince45::new(dim, control), &mut sys), 0, "{name}: dopri45");
        let mut scratch = sim::control::TargetScratch::new(scene.model());
        let nv = scene.model().nv;
        let (mut q, mut qd, mut qdd) = (vec![0.0; nv], vec![0.0; nv], vec![0.0; nv]);
        let before = allocs();
        for k in 0..100 {
            let t = k as f64 * 0.05;
            let _ = scene.target().hand_desired(t, scene.model(), scene.hand(), &mut scratch);
            scene.target().eval(t, scene.model(), scene.hand(), &mut scratch, &mut q, &mut qd, Some(&mut qdd)).unwrap();
        }
        assert_eq!(allocs() - before, 0, "{name}: Target::eval, hand_desired");
    }
    let scene = Scene::paper().unwrap();
    let mut scratch = sim::control::TargetScratch::new(scene.model());
    let (mut q, mut qd, mut qdd) = (vec![0.0; 10], vec![0.0; 10], vec![0.0; 10]);
    let before = allocs();
    for k in 0..100 {
        scene.target().eval(k as f64 * 0.05, scene.model(), scene.hand(), &mut scratch, &mut q, &mut qd, Some(&mut qdd)).unwrap();
    }
    assert_eq!(allocs() - before, 0, "paper target with q̈_d");
}

/// A ball, y = [h, v], h'' = -9.81, bouncing with restitution 0.8 (event h = 0 downwards).
struct Ball;

impl OdeSystem for Ball {
    type Error = std::convert::Infallible;
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&mut self, _t: f64, y: &[f64], dydt: &mut [f64]) -> Result<(), Self::Error> {
        dydt[0] = y[1];
        dydt[1] = -9.81;
        Ok(())
    }
}

impl HybridSystem for Ball {
    fn n_events(&self) -> usize {
        1
    }
    fn event_direction(&self, _i: usize) -> i8 {
        -1
    }
    fn events(&mut self, _t: f64, y: &[f64], out: &mut [f64]) -> Result<(), Self::Error> {
        out[0] = y[0];
        Ok(())
    }
    fn init_modes(&mut self, _t: f64, _y: &mut [f64]) -> Result<bool, Self::Error> {
        Ok(false)
    }
    fn handle_events(&mut self, _t: f64, y: &mut [f64], _fired: &[bool]) -> Result<bool, Self::Error> {
        y[1] *= -0.8;
        Ok(true)
    }
}

/// The event driver allocates per run (its buffers), not per step nor per event: the same
/// count for a ball run (2 s, 3 bounces) with steps of at most 1e-2 s and 1e-3 s (rk4: 1e-3
/// and 1e-4 s), root finding and restarts included.
#[test]
fn the_event_driver_does_not_allocate_per_step_or_event() {
    let count = |st: &mut dyn Stepper<Ball>| {
        let (mut bounces, mut v_last) = (0, 0.0);
        let before = allocs();
        integrate_hybrid(st, &mut Ball, 0.0, &[1.0, 0.0], 2.0, 1e-2, None, EventSettings::default(), |_, y, _| {
            if y[1] > 0.0 && v_last <= 0.0 {
                bounces += 1;
            }
            v_last = y[1];
            Ok(())
        })
        .unwrap();
        (allocs() - before, bounces)
    };
    let c = |h_max: f64| StepControl { h_max, ..StepControl::new(1e-9, 1e-12) };
    for (name, (a, na), (b, nb)) in [
        ("dopri45, h_max 1e-2 / 1e-3", count(&mut DormandPrince45::new(2, c(1e-2))), count(&mut DormandPrince45::new(2, c(1e-3)))),
        ("rk4, h 1e-3 / 1e-4", count(&mut Rk4::new(2, 1e-3)), count(&mut Rk4::new(2, 1e-4))),
    ] {
        assert_eq!((na, nb), (3, 3), "{name}: bounces at 0.45, 1.17, 1.75 s");
        assert_eq!(a, b, "{name}: {a} vs {b} allocations");
    }
}

/// The sticking gears' holding torques where they are not unique allocate nothing per
/// evaluation: the paper arm's two-elbow chain with efficiency-only gears
/// (`scenes/drives/paper_efficiency_gears.json`), where several joints of the chain stick at
/// once and `ode/gear_hold.rs` chooses among their torques by Newton's method on scratch (the
/// old solve's choice left a band at 0.154 s); 20 right-hand sides at every sample of the first
/// 0.5 s with two or more joints sticking.
#[test]
#[allow(clippy::result_large_err)] // the sink returns RunError, as `sim::run`'s
fn the_holding_torques_of_a_closed_chain_do_not_allocate() {
    use sim::dynamics::gear_friction::GearMode;
    let file = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/drives/paper_efficiency_gears.json");
    let scene = Scene::load(std::path::Path::new(file)).unwrap().vary(|s| s.duration = 0.5).unwrap();
    let run = scene.run("two-elbow").unwrap().clone();
    let mut sys = ArmSystem::new(&scene, &run);
    let y0 = sys.initial_state();
    let mut dydt = vec![0.0; y0.len()];
    let (mut checked, mut worst) = (0, 0);
    scene
        .integrator()
        .integrate_hybrid(&mut sys, &y0, 0.5, 1e-3, None, EventSettings::default(), |t, y, sys| {
            let mut mode = [None; 10];
            for e in sys.gear_events() {
                mode[e.joint] = Some(e.mode);
            }
            if mode.iter().filter(|m| **m == Some(GearMode::Stick)).count() >= 2 {
                let before = allocs();
                for _ in 0..20 {
                    sys.rhs(t, y, &mut dydt)?;
                }
                worst = worst.max(allocs() - before);
                checked += 1;
            }
            Ok(())
        })
        .unwrap();
    assert!(checked >= 100, "{checked} samples with two joints sticking");
    assert_eq!(worst, 0, "allocations per 20 evaluations");
}
