//! Shared pieces of the contact acceptance tests (`contacts_*.rs`, issue 11): the small robots
//! (a point mass on three prismatic joints, a rod on two prismatic joints and a revolute one, a
//! planar double pendulum), scene JSON built around them with the scene syntax of the contact
//! design (`model`, `restitution`, `friction`, `events`), and a run that keeps every sample and
//! every contact event (`Outputs::events`, drained by the run at each sample).
//!
//! Frames: world z up, the table is the plane `z = 0` (normal +z, offset 0 m), whose tangent
//! basis is (t1, t2) = (x, y) (`tangent_basis`). SI units throughout.

#![allow(dead_code)] // each test file uses part of it

use serde_json::{json, Value};
use sim::dynamics::contact::{ContactEvent, ContactEventKind, ContactMode};
use sim::error::RunError;
use sim::ode::Outputs;
use sim::run::RunReport;
use sim::scene::Scene;

pub const G: f64 = 9.81;

/// A point mass of `mass` kg at the origin of link `ball`, moved by three prismatic joints x,
/// y, z (axes world x, y, z, all at the world origin): q = the ball's world position, m. The two
/// carriages are massless (no `<inertial>`), so M = m I₃ exactly. The ball's inertia is
/// irrelevant (no joint rotates it).
pub fn point_urdf(mass: f64) -> String {
    let lim = r#"<limit lower="-1000" upper="1000" effort="1e6" velocity="1e3"/>"#;
    format!(
        r#"<?xml version="1.0"?>
<robot name="point">
  <link name="base"/>
  <joint name="x" type="prismatic"><parent link="base"/><child link="cx"/><origin xyz="0 0 0"/><axis xyz="1 0 0"/>{lim}</joint>
  <link name="cx"/>
  <joint name="y" type="prismatic"><parent link="cx"/><child link="cy"/><origin xyz="0 0 0"/><axis xyz="0 1 0"/>{lim}</joint>
  <link name="cy"/>
  <joint name="z" type="prismatic"><parent link="cy"/><child link="ball"/><origin xyz="0 0 0"/><axis xyz="0 0 1"/>{lim}</joint>
  <link name="ball"><inertial><origin xyz="0 0 0"/><mass value="{mass}"/><inertia ixx="1e-3" ixy="0" ixz="0" iyy="1e-3" iyz="0" izz="1e-3"/></inertial></link>
</robot>"#
    )
}

/// A uniform rod of `mass` kg and length `2 half` m in the x–z plane: prismatic x, prismatic z
/// (its centre's world position) and a revolute joint about world y (angle φ; the rod's axis is
/// its link's x axis, pointing at `(cos φ, 0, −sin φ)` in the world). Inertia about the centre
/// `m (2l)² / 12 = m l² / 3` about y (and z); the carriages are massless.
pub fn rod_urdf(mass: f64, half: f64) -> String {
    let lim = r#"<limit lower="-1000" upper="1000" effort="1e6" velocity="1e3"/>"#;
    let i = mass * half * half / 3.0;
    format!(
        r#"<?xml version="1.0"?>
<robot name="rod">
  <link name="base"/>
  <joint name="x" type="prismatic"><parent link="base"/><child link="cx"/><origin xyz="0 0 0"/><axis xyz="1 0 0"/>{lim}</joint>
  <link name="cx"/>
  <joint name="z" type="prismatic"><parent link="cx"/><child link="cz"/><origin xyz="0 0 0"/><axis xyz="0 0 1"/>{lim}</joint>
  <link name="cz"/>
  <joint name="pitch" type="continuous"><parent link="cz"/><child link="rod"/><origin xyz="0 0 0"/><axis xyz="0 1 0"/></joint>
  <link name="rod"><inertial><origin xyz="0 0 0"/><mass value="{mass}"/><inertia ixx="1e-6" ixy="0" ixz="0" iyy="{i}" iyz="0" izz="{i}"/></inertial></link>
</robot>"#
    )
}

/// The double pendulum of `contacts_pendulum.rs`: the shoulder `joint1` at (0, 0, h) and the
/// elbow `joint2` at the end of link1, both revolute about world y; uniform rods along their
/// links' x axes (link1: m1, l1; link2: m2, l2), inertia `m l² / 12` about the centre.
pub struct DoublePendulum {
    pub h: f64,
    pub l1: f64,
    pub m1: f64,
    pub l2: f64,
    pub m2: f64,
}

impl DoublePendulum {
    pub fn urdf(&self) -> String {
        let DoublePendulum { h, l1, m1, l2, m2 } = *self;
        let (i1, i2) = (m1 * l1 * l1 / 12.0, m2 * l2 * l2 / 12.0);
        format!(
            r#"<?xml version="1.0"?>
<robot name="double_pendulum">
  <link name="base"/>
  <joint name="joint1" type="revolute"><parent link="base"/><child link="link1"/><origin xyz="0 0 {h}"/><axis xyz="0 1 0"/><limit lower="-10" upper="10" effort="1e6" velocity="1e3"/></joint>
  <link name="link1"><inertial><origin xyz="{c1} 0 0"/><mass value="{m1}"/><inertia ixx="1e-6" ixy="0" ixz="0" iyy="{i1}" iyz="0" izz="{i1}"/></inertial></link>
  <joint name="joint2" type="revolute"><parent link="link1"/><child link="link2"/><origin xyz="{l1} 0 0"/><axis xyz="0 1 0"/><limit lower="-10" upper="10" effort="1e6" velocity="1e3"/></joint>
  <link name="link2"><inertial><origin xyz="{c2} 0 0"/><mass value="{m2}"/><inertia ixx="1e-6" ixy="0" ixz="0" iyy="{i2}" iyz="0" izz="{i2}"/></inertial></link>
</robot>"#,
            c1 = l1 / 2.0,
            c2 = l2 / 2.0
        )
    }
}

/// A scene around a robot whose joints are all passive (no motor: pure mechanics, the
/// `motor`/`controller` entries are required by the syntax but act on no joint), no joint
/// damping, a constant joint target (unused by passive joints), dopri45 at `rtol` (atol =
/// rtol / 100), one run `r` with the given contacts.
pub fn passive_scene(hand_link: &str, joints: &[&str], q0: &[f64], qd0: &[f64], gravity: [f64; 3], duration: f64, rtol: f64) -> Value {
    json!({
        "name": "contact-test",
        "urdf": "robot.urdf",
        "gravity": gravity,
        "duration": duration,
        "output_rate": 1000.0,
        "joint_damping": 0.0,
        "motor": {"torque_constant": 0.5, "resistance": 1.0, "inductance": 0.0, "rotor_inertia": 1e-5,
                  "gear_ratio": 1.0, "gear_damping": 0.0},
        "controller": {"kp": 0.0, "kd": 0.0},
        "passive": joints,
        "hand": {"link": hand_link},
        "target": {"kind": "joint-spline", "waypoints": [{"t": 0.0, "q": q0}, {"t": 1.0, "q": q0}]},
        "initial": {"q": q0, "qd": qd0},
        "contacts": [],
        "integrator": {"method": "dopri45", "rtol": rtol, "atol": rtol * 1e-2},
        "runs": [{"name": "r", "contacts": []}]
    })
}

/// Add the contact `name` at `point` on the table z = 0 with the given extra keys (`model`,
/// `restitution`, `friction`, ...), active in run `r`.
pub fn add_table_contact(scene: &mut Value, name: &str, point: Value, keys: Value) {
    let mut c = json!({"name": name, "point": point, "plane": {"normal": [0.0, 0.0, 1.0], "offset": 0.0}});
    for (k, v) in keys.as_object().expect("contact keys are an object") {
        c[k] = v.clone();
    }
    scene["contacts"].as_array_mut().unwrap().push(c);
    scene["runs"][0]["contacts"].as_array_mut().unwrap().push(json!(name));
}

pub fn load(scene: &Value, urdf: &str) -> Scene {
    try_load(scene, urdf).unwrap_or_else(|e| panic!("the test scene is valid: {e}\n{scene:#}"))
}

pub fn try_load(scene: &Value, urdf: &str) -> Result<Scene, sim::error::SceneError> {
    let urdf = urdf.to_string();
    Scene::from_json(&scene.to_string(), "contact-test.json", move |_| Ok(urdf.clone()))
}

/// Every sample of a run and every contact event (in time order), with the report.
pub struct Collected {
    pub samples: Vec<Outputs>,
    pub events: Vec<ContactEvent>,
    pub report: RunReport,
}

impl Collected {
    pub fn events_of(&self, kind: ContactEventKind) -> Vec<&ContactEvent> {
        self.events.iter().filter(|e| e.kind == kind).collect()
    }

    /// The samples at times t with `from < t < to`.
    pub fn between(&self, from: f64, to: f64) -> impl Iterator<Item = &Outputs> {
        self.samples.iter().filter(move |o| o.t > from && o.t < to)
    }
}

#[allow(clippy::result_large_err)] // RunError carries schemas::Error, as in `sim::run::simulate`
pub fn try_collect(scene: &Scene, run: &str) -> Result<Collected, RunError> {
    let r = scene.run(run).unwrap_or_else(|| panic!("no run {run}")).clone();
    let (mut samples, mut events) = (Vec::new(), Vec::new());
    let report = sim::run::simulate(scene, &r, |o| {
        events.extend_from_slice(&o.events);
        samples.push(o.clone());
        Ok(())
    })?;
    Ok(Collected { samples, events, report })
}

pub fn collect(scene: &Scene, run: &str) -> Collected {
    try_collect(scene, run).unwrap_or_else(|e| panic!("run {run}: {e}"))
}

/// A contact is in touch (carries a force or may): sticking or sliding.
pub fn touching(m: ContactMode) -> bool {
    matches!(m, ContactMode::Sticking | ContactMode::Sliding)
}

/// The root of `f` on `[a, b]` (f(a), f(b) of opposite signs) by bisection to the last bit.
pub fn bisect(mut a: f64, mut b: f64, f: impl Fn(f64) -> f64) -> f64 {
    let fa = f(a);
    assert!(fa * f(b) <= 0.0, "no sign change on [{a}, {b}]");
    for _ in 0..200 {
        let m = 0.5 * (a + b);
        if m <= a || m >= b {
            break;
        }
        if f(m) * fa > 0.0 {
            a = m;
        } else {
            b = m;
        }
    }
    0.5 * (a + b)
}

/// The contact audit (`schemas::ContactAuditor`, the one `sim` and `analyze` run) over every
/// sample of a collected run: the record of the run's contacts and event settings, then each
/// sample's `/contacts` message as the recorder fills it.
pub fn audit(scene: &Scene, run: &str, c: &Collected) -> schemas::ContactAudit {
    let r = scene.run(run).unwrap_or_else(|| panic!("no run {run}"));
    let contacts = scene.run_contact_models(r);
    let record = sim::record::contacts_record(&contacts, &scene.contact_settings());
    let mut auditor = schemas::ContactAuditor::new(&record);
    let mut cs = schemas::messages::ContactState { name: contacts.iter().map(|k| k.name().to_string()).collect(), ..Default::default() };
    for o in &c.samples {
        cs.time = o.t;
        cs.mode = o.contacts.iter().map(|k| k.mode.code()).collect();
        cs.gap = o.contacts.iter().map(|k| k.gap).collect();
        cs.gap_rate = o.contacts.iter().map(|k| k.gap_rate).collect();
        cs.normal_force = o.contacts.iter().map(|k| k.normal_force).collect();
        cs.friction_force_t1 = o.contacts.iter().map(|k| k.friction_force[0]).collect();
        cs.friction_force_t2 = o.contacts.iter().map(|k| k.friction_force[1]).collect();
        cs.slip_velocity_t1 = o.contacts.iter().map(|k| k.slip_velocity[0]).collect();
        cs.slip_velocity_t2 = o.contacts.iter().map(|k| k.slip_velocity[1]).collect();
        auditor.sample(o.t, &cs);
    }
    auditor.finish()
}

/// The largest |balance residual| over the samples relative to the energy scale of the run:
/// `Σ_j |E_j(t_end)|` plus the largest kinetic and |potential| energy met (a passive run draws
/// no electric energy), and that scale.
pub fn balance(c: &Collected) -> (f64, f64) {
    let e: f64 = c.samples.last().unwrap().electric_energy.iter().map(|x| x.abs()).sum();
    let mech = c.samples.iter().map(|o| o.kinetic.abs().max(o.potential.abs())).fold(0.0, f64::max);
    let scale = e.max(mech);
    let worst = c.samples.iter().map(|o| o.balance_residual.abs()).fold(0.0, f64::max);
    (worst / scale, scale)
}
