//! Evaluates the paper scene's right-hand side repeatedly, for profilers
//! (`valgrind --tool=callgrind target/release/examples/rhs_profile`).
use sim::integrate::OdeSystem;
fn main() {
    let scene = sim::scene::Scene::paper().expect("built-in scene");
    let run = scene.run("two-elbow").expect("run").clone();
    let mut sys = sim::ode::ArmSystem::new(&scene, &run);
    let y = sys.initial_state();
    let mut f = vec![0.0; y.len()];
    let n: usize = std::env::args().nth(1).and_then(|a| a.parse().ok()).unwrap_or(20_000);
    let t0 = std::time::Instant::now();
    for k in 0..n {
        sys.rhs(k as f64 * 1e-5, &y, &mut f).expect("rhs");
    }
    println!("{:.3} us per RHS", t0.elapsed().as_secs_f64() / n as f64 * 1e6);
}
