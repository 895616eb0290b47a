//! `sim check`: validate a scene and describe it, without running it.

use std::fmt::Write as _;
use std::path::PathBuf;

use anyhow::Result;
use cli::{exit, print_out};
use serde::Serialize;
use sim::dynamics::forward::Stabilization;
use sim::scene::Scene;

/// Validate a scene file (every check a run makes before it starts) and describe what it
/// holds: the robot, the contacts, the runs and the settings.
#[derive(Debug, Clone, clap::Args)]
#[command(after_help = "\
Output: a description for people, or -f json (robot, contacts, runs, duration, output rate,
integrator and its settings, model). Exit status 2 and the file, field and value when the scene
is not valid.

Examples:
  sim check                            the built-in paper scene
  sim check hobby-arm                  a built-in scene by name (`sim list`)
  sim check sim/scenes/hard/stiff-motor.json
  sim check my_scene.json -f json")]
pub struct CheckArgs {
    /// Scene JSON file, or the name of a built-in scene (`sim list`) [default: the built-in paper
    /// scene].
    #[arg(value_name = "SCENE")]
    pub scene: Option<PathBuf>,
    /// table: a description for people; json: the same for machines.
    #[arg(short = 'f', long = "format", value_enum, default_value = "table")]
    pub format: DescribeFormat,
}

/// How `sim check` prints its description.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum DescribeFormat {
    Table,
    Json,
}

/// What a valid scene describes.
#[derive(Debug, Serialize)]
struct Description {
    scene: String,
    source: String,
    robot: String,
    joints: Vec<String>,
    moving_mass_kg: f64,
    contacts: Vec<String>,
    /// Each contact's model and parameters, when some contact is not bilateral (issue 11).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    contact_models: Vec<String>,
    runs: Vec<RunDescription>,
    duration_s: f64,
    output_rate_hz: f64,
    integrator: IntegratorDescription,
    mass_matrix: String,
    constraint_solver: String,
    stabilization: String,
    motors: &'static str,
    /// What the arm is asked to do (`target`).
    target: String,
    /// The controller's law.
    controller: String,
    /// Drive limits and passive joints, and how the URDF's joint limits are treated.
    limits: String,
    /// Locked joints, mimic followers, repaired inertias, meshes (empty when none).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    robot_options: Vec<String>,
    /// The datasheet drives' derived model, joints with equal drives grouped (scenes with
    /// `drives` or `thermal`).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    drives: Vec<DriveDescription>,
    /// The thermal model: ambient and initial temperature, °C (scenes with `thermal`).
    #[serde(skip_serializing_if = "Option::is_none")]
    thermal: Option<String>,
}

/// One group of joints with the same drive, as the model sees it (link side, SI).
#[derive(Debug, Clone, Serialize, PartialEq)]
struct DriveDescription {
    joints: Vec<String>,
    /// Catalogue names, or "datasheet values" / "motor values" (the scene's `motor`).
    drive: String,
    km_nm_per_a: f64,
    ke_v_s_per_rad: f64,
    jm_kg_m2: f64,
    dm_nm_s_per_rad: f64,
    /// R at the ambient (thermal model on) or at the datasheet's reference temperature, ohm.
    resistance_ohm: f64,
    resistance_at_c: Option<f64>,
    inductance_h: f64,
    gear_ratio_note: Option<String>,
    #[serde(skip_serializing_if = "Option::is_none")]
    nominal_voltage_v: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    thermal: Option<ThermalDescription>,
}

/// A motor's thermal constants (`dynamics/thermal.rs`).
#[derive(Debug, Clone, Copy, Serialize, PartialEq)]
struct ThermalDescription {
    c_winding_j_per_k: f64,
    c_housing_j_per_k: f64,
    r_winding_housing_k_per_w: f64,
    r_housing_ambient_k_per_w: f64,
    tau_winding_s: f64,
    tau_housing_s: f64,
    max_winding_temperature_c: f64,
    alpha_20_per_k: f64,
    reference_temperature_c: f64,
}

fn drive_descriptions(s: &Scene) -> Vec<DriveDescription> {
    if s.datasheets().iter().all(Option::is_none) && s.thermal().is_none() {
        return Vec::new();
    }
    let (d, names) = (s.drives(), s.model().joint_names());
    let mut out: Vec<DriveDescription> = Vec::new();
    for (j, name) in names.iter().enumerate() {
        if d.passive[j] {
            continue;
        }
        let ds = &s.datasheets()[j];
        let th = s.thermal();
        let params = th.and_then(|t| t.params[j]).or_else(|| ds.as_ref().and_then(|x| x.thermal));
        let (resistance_ohm, resistance_at_c) = match (th, &params) {
            (Some(t), _) => (t.resistance(j, t.ambient), Some(t.ambient)),
            (None, Some(p)) => (d.r[j], Some(p.reference_temperature)),
            (None, None) => (d.r[j], None),
        };
        let desc = DriveDescription {
            joints: vec![name.clone()],
            drive: ds.as_ref().map_or("motor values".into(), |x| x.what.clone()),
            km_nm_per_a: d.km[j],
            ke_v_s_per_rad: d.ke[j],
            jm_kg_m2: d.jm[j],
            dm_nm_s_per_rad: d.dm[j],
            resistance_ohm,
            resistance_at_c,
            inductance_h: d.l[j],
            gear_ratio_note: ds.as_ref().and_then(|x| {
                let mut parts = Vec::new();
                if let Some(e) = x.gear_efficiency {
                    parts.push(format!("max efficiency {:.0} % (not modelled: no gear friction model in this drive)", 100.0 * e));
                }
                if let Some(t) = x.gear_torque_continuous {
                    parts.push(format!("{t} N m continuous"));
                }
                if let Some(t) = x.gear_torque_intermittent {
                    parts.push(format!("{t} N m intermittent (monitored)"));
                }
                (!parts.is_empty()).then(|| parts.join(", "))
            }),
            nominal_voltage_v: ds.as_ref().map(|x| x.nominal_voltage),
            thermal: params.map(|p| ThermalDescription {
                c_winding_j_per_k: p.c_winding(),
                c_housing_j_per_k: p.c_housing(),
                r_winding_housing_k_per_w: p.r_winding_housing,
                r_housing_ambient_k_per_w: p.r_housing_ambient,
                tau_winding_s: p.tau_winding,
                tau_housing_s: p.tau_housing,
                max_winding_temperature_c: p.max_winding_temperature,
                alpha_20_per_k: p.alpha_20,
                reference_temperature_c: p.reference_temperature,
            }),
        };
        match out.iter_mut().find(|o| DriveDescription { joints: o.joints.clone(), ..desc.clone() } == **o) {
            Some(o) => o.joints.push(name.clone()),
            None => out.push(desc),
        }
    }
    out
}

/// Joint names as a range when they are many: `joint1 … joint10 (10)`.
fn joint_list(j: &[String]) -> String {
    if j.len() <= 3 { j.join(", ") } else { format!("{} … {} ({} joints)", j[0], j[j.len() - 1], j.len()) }
}

fn drive_lines(d: &DriveDescription) -> Vec<String> {
    let at = d.resistance_at_c.map_or(String::new(), |t| format!(" at {t} °C"));
    let mut out = vec![format!(
        "{}: {}; K_m = {:.6} N m/A, K_e k = {:.6} V s/rad, J_m = {:.6e} kg m^2, D_m = {:.4e} N m s/rad, R = {:.6} ohm{at}, L = {:.4e} H{}",
        joint_list(&d.joints),
        d.drive,
        d.km_nm_per_a,
        d.ke_v_s_per_rad,
        d.jm_kg_m2,
        d.dm_nm_s_per_rad,
        d.resistance_ohm,
        d.inductance_h,
        d.nominal_voltage_v.map_or(String::new(), |v| format!(", nominal {v} V")),
    )];
    if let Some(t) = &d.thermal {
        out.push(format!(
            "  thermal: C_w = {:.4} J/K, C_h = {:.4} J/K (R_th1 = {} K/W, R_th2 = {} K/W, tau_w = {} s, tau_s = {} s), T_max = {} °C, alpha_20 = {} /K, R given at {} °C",
            t.c_winding_j_per_k, t.c_housing_j_per_k, t.r_winding_housing_k_per_w, t.r_housing_ambient_k_per_w, t.tau_winding_s, t.tau_housing_s, t.max_winding_temperature_c, t.alpha_20_per_k, t.reference_temperature_c
        ));
    }
    if let Some(g) = &d.gear_ratio_note {
        out.push(format!("  gearhead: {g}"));
    }
    out
}

/// The integrator with every setting that applies, defaults filled in.
#[derive(Debug, Serialize)]
struct IntegratorDescription {
    method: &'static str,
    #[serde(skip_serializing_if = "Option::is_none")]
    step: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    rtol: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    atol: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    h_max: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    max_steps: Option<u64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    jacobian_reuse: Option<u64>,
    /// The same in one phrase.
    phrase: String,
}

#[derive(Debug, Serialize)]
struct RunDescription {
    name: String,
    contacts: Vec<String>,
}

/// The compact JSON of a setting, without quotes for a plain name (`crba`).
fn text<T: Serialize>(v: &T) -> String {
    serde_json::to_string(v).unwrap_or_default().trim_matches('"').to_string()
}

/// A contact model in words, with its parameters.
fn model_phrase(m: &sim::dynamics::contact::ContactModel) -> String {
    use sim::dynamics::contact::ContactModel as M;
    match *m {
        M::Bilateral => "bilateral".into(),
        M::Unilateral { restitution, friction } => format!("unilateral, restitution {restitution}, friction {friction}"),
        M::Compliant { stiffness, damping, friction, slip_velocity } => {
            format!("compliant, stiffness {stiffness} N/m, damping {damping} N s/m, friction {friction}, slip velocity {slip_velocity} m/s")
        }
    }
}

fn describe(s: &Scene) -> Description {
    Description {
        scene: s.spec().name.clone(),
        source: s.source().to_string(),
        robot: s.model().name.clone(),
        joints: s.model().joint_names(),
        moving_mass_kg: s.model().total_mass(),
        contacts: s.contacts().iter().map(|c| c.name.clone()).collect(),
        contact_models: if s.contact_models().iter().all(|c| c.model == sim::dynamics::contact::ContactModel::Bilateral) {
            Vec::new()
        } else {
            s.contact_models().iter().map(|c| format!("{}: {}", c.name(), model_phrase(&c.model))).collect()
        },
        runs: s
            .runs()
            .iter()
            .map(|r| RunDescription { name: r.name.clone(), contacts: r.contacts.iter().map(|&k| s.contacts()[k].name.clone()).collect() })
            .collect(),
        duration_s: s.duration(),
        output_rate_hz: s.output_rate(),
        integrator: {
            let i = s.integrator().describe();
            IntegratorDescription {
                method: s.integrator().method(),
                step: i.step,
                rtol: i.rtol,
                atol: i.atol,
                h_max: i.h_max,
                max_steps: i.max_steps,
                jacobian_reuse: i.jacobian_reuse,
                phrase: i.phrase(),
            }
        },
        mass_matrix: text(&s.mass_matrix()),
        constraint_solver: text(&s.solver()),
        stabilization: match s.stabilization() {
            Stabilization::None => "none (eq 15 alone)".into(),
            Stabilization::Baumgarte { alpha, beta } => format!("Baumgarte, alpha = {alpha} 1/s, beta = {beta} 1/s"),
            Stabilization::Projection => "projection onto C = 0, C' = 0 after every step".into(),
        },
        motors: s.drives().electrical.describe(),
        target: s.target().describe(s.model()),
        controller: s.controller().law.name().to_string(),
        limits: limits_phrase(s),
        robot_options: robot_options(s),
        drives: drive_descriptions(s),
        thermal: s.thermal().map(|t| format!("two-node winding/housing model on: ambient {} °C, initial {} °C; R(T_w) in eq 11; temperatures recorded on /motor_temperatures", t.ambient, t.initial)),
    }
}

fn limits_phrase(s: &Scene) -> String {
    let (d, names) = (s.drives(), s.model().joint_names());
    let mut parts = Vec::new();
    let finite = |v: &[f64]| v.iter().filter(|x| x.is_finite()).count();
    if finite(d.voltage_limit.as_slice()) > 0 {
        parts.push(format!("supply voltage limited on {} joints", finite(d.voltage_limit.as_slice())));
    }
    if finite(d.current_limit.as_slice()) > 0 {
        parts.push(format!("current limited on {} joints", finite(d.current_limit.as_slice())));
    }
    let passive: Vec<&str> = names.iter().zip(&d.passive).filter(|(_, &p)| p).map(|(n, _)| n.as_str()).collect();
    if !passive.is_empty() {
        parts.push(format!("passive: {}", passive.join(", ")));
    }
    parts.push(match s.stops() {
        Some(_) => "URDF position limits enforced by soft stops, speed and effort limits watched".into(),
        None => "URDF position, speed and effort limits watched (flagged when crossed)".into(),
    });
    parts.join("; ")
}

fn robot_options(s: &Scene) -> Vec<String> {
    let m = s.model();
    let mut out: Vec<String> = m.locked.iter().map(|(j, v)| format!("locked {j} at {v}")).collect();
    out.extend(m.mimics.iter().map(|x| format!("mimic {} locked at {} with {}", x.follower, x.locked_at, x.leader)));
    out.extend(sim::dynamics::model::repair_summary(&m.repaired_inertias).map(|r| format!("repaired inertias: {r}")));
    out.extend(sim::dynamics::urdf::mesh_summary(s.meshes()).map(|r| format!("meshes: {r}")));
    out
}

pub fn run(a: &CheckArgs) -> Result<u8> {
    let s = crate::load_scene(a.scene.as_deref())?;
    let d = describe(&s);
    let text = match a.format {
        DescribeFormat::Json => serde_json::to_string_pretty(&d)? + "\n",
        DescribeFormat::Table => {
            let mut o = String::new();
            let joints = if d.joints.len() <= 12 {
                d.joints.join(", ")
            } else {
                format!("{} … {}", d.joints[..3].join(", "), d.joints[d.joints.len() - 2..].join(", "))
            };
            writeln!(o, "scene `{}` ({}) is valid", d.scene, d.source)?;
            writeln!(o, "  robot        {}: {} joints ({joints}), {:.3} kg moving", d.robot, d.joints.len(), d.moving_mass_kg)?;
            writeln!(o, "  contacts     {}", if d.contacts.is_empty() { "none".into() } else { d.contacts.join(", ") })?;
            for m in &d.contact_models {
                writeln!(o, "  contact      {m}")?;
            }
            for r in &d.runs {
                writeln!(o, "  run          {}: contacts [{}]", r.name, r.contacts.join(", "))?;
            }
            writeln!(o, "  time         {} s, recorded at {} Hz", d.duration_s, d.output_rate_hz)?;
            writeln!(o, "  integrator   {}", d.integrator.phrase)?;
            writeln!(o, "  dynamics     mass matrix {}, constraint solver {}, stabilisation {}", d.mass_matrix, d.constraint_solver, d.stabilization)?;
            writeln!(o, "  motors       {}", d.motors)?;
            writeln!(o, "  target       {}", d.target)?;
            writeln!(o, "  controller   {}", d.controller)?;
            writeln!(o, "  limits       {}", d.limits)?;
            for r in &d.robot_options {
                writeln!(o, "  urdf         {r}")?;
            }
            if let Some(t) = &d.thermal {
                writeln!(o, "  thermal      {t}")?;
            }
            for dd in &d.drives {
                for line in drive_lines(dd) {
                    writeln!(o, "  drive        {line}")?;
                }
            }
            o
        }
    };
    print_out(&text)?;
    Ok(exit::SUCCESS)
}
