//! Validation of the scene's `target` into a [`Target`] ([`crate::control::target`]), and of
//! `"initial": {"q": "from-target"}`. Errors name the field (`target.path.radius`), the value
//! and why; a CSV's errors name the file, line and column; a path the general IK cannot follow
//! names the time and the residual.

use nalgebra::UnitQuaternion;

use super::spec::{
    Branch, Direction, InitialQ, Interpolation, KindedTarget, PathSpec, PointsSpec, SceneSpec, TargetSpec,
};
use super::ctx::{names, positive, Ctx};
use crate::control::general_ik::{track, GeneralIk, DEFAULT_GRID_STEP, MAX_KNOTS};
use crate::limits::MAX_TARGET_VALUES;
use crate::control::path::{CartesianPath, CirclePath};
use crate::control::spline::{CubicSpline, JointSpline, MinJerk};
use crate::control::{Circle, Target, TargetScratch, YawPlanarIk};
use crate::dynamics::constraints::PointOnPlane;
use crate::dynamics::kinematics::BodyPoint;
use crate::dynamics::Model;
use crate::error::SceneError;

/// Largest interpolation error of a Cartesian target between its grid's knots, m (or rad).
pub const MAX_BETWEEN_KNOTS: f64 = 1e-9;

/// The validated target, and q0 (the numeric `initial.q`, or q_d(0) for `"from-target"`).
pub(super) fn build_target(
    c: &Ctx,
    spec: &SceneSpec,
    model: &Model,
    hand: &BodyPoint,
    duration: f64,
    csv_text: Option<&str>,
) -> Result<(Target, Vec<f64>), SceneError> {
    let nv = model.nv;
    let q_init = match &spec.initial.q {
        InitialQ::Values(p) => Some(c.per_joint("initial.q", p, nv, |_| true, "")?),
        InitialQ::FromTarget => None,
    };
    let target = match &spec.target {
        TargetSpec::Paper(p) => {
            let Some(q0) = &q_init else {
                return Err(c.err("initial.q", "\"from-target\"", "the paper's target (circle + closed-form ik) needs numeric initial angles: they fix the held joints"));
            };
            let cs = &p.circle;
            let circle = Circle {
                center: c.vec3("target.circle.center", cs.center)?,
                radius: c.number("target.circle.radius", cs.radius, positive, "must be > 0 m")?,
                period: c.number("target.circle.period", cs.period, positive, "must be > 0 s")?,
                phase: c.number("target.circle.phase", cs.phase, |_| true, "")?,
                direction: match cs.direction {
                    Direction::CounterClockwise => 1.0,
                    Direction::Clockwise => -1.0,
                },
                step: match &cs.step {
                    Some(st) => Some((
                        c.number("target.circle.step.time", st.time, |_| true, "")?,
                        c.vec3("target.circle.step.offset", st.offset)?,
                    )),
                    None => None,
                },
            };
            let iks = &p.ik;
            let yaw = c.dof("target.ik.yaw_joint", model, &iks.yaw_joint)?;
            let p1 = c.dof("target.ik.planar_joints[0]", model, &iks.planar_joints[0])?;
            let p2 = c.dof("target.ik.planar_joints[1]", model, &iks.planar_joints[1])?;
            let branch = if iks.branch == Branch::Positive { 1.0 } else { -1.0 };
            let ik = YawPlanarIk::new(model, q0, yaw, [p1, p2], hand, branch)
                .map_err(|e| c.err("target.ik", format!("{} + {:?}", iks.yaw_joint, iks.planar_joints), e.to_string()))?;
            // the whole path must be reachable: check it densely before running
            let mut qdes = vec![0.0; nv];
            let mut qd_des = vec![0.0; nv];
            let n_check = 2000;
            for s in 0..=n_check {
                let t = duration * s as f64 / n_check as f64;
                ik.solve(&circle.position(t), &circle.velocity(t), &mut qdes, &mut qd_des)
                    .map_err(|why| c.err("target", format!("t = {t:.4} s"), why))?;
            }
            Target::Paper { circle, ik }
        }
        TargetSpec::Kinded(KindedTarget::JointSpline(js)) => {
            let f = "target.waypoints";
            if js.waypoints.is_empty() {
                return Err(c.err(f, "[]", "needs at least one waypoint"));
            }
            let mut t = Vec::with_capacity(js.waypoints.len());
            let mut y = Vec::with_capacity(js.waypoints.len() * nv);
            for (k, w) in js.waypoints.iter().enumerate() {
                let tk = c.number(&format!("{f}[{k}].t"), w.t, |_| true, "")?;
                if let Some(&prev) = t.last() {
                    if tk <= prev {
                        return Err(c.err(format!("{f}[{k}].t"), tk, format!("must be after the previous waypoint's t = {prev} s")));
                    }
                }
                if w.q.len() != nv {
                    return Err(c.err(format!("{f}[{k}].q"), format!("an array of {}", w.q.len()), format!("needs one angle per joint ({nv}, in the order {})", model.joint_names().join(", "))));
                }
                for (j, &x) in w.q.iter().enumerate() {
                    c.number(&format!("{f}[{k}].q[{j}]"), x, |_| true, "")?;
                }
                t.push(tk);
                y.extend_from_slice(&w.q);
            }
            Target::Joint(match js.interpolation {
                Interpolation::Cubic => JointSpline::Cubic(CubicSpline::at_rest(t, y, nv).map_err(|why| c.err(f, "", why))?),
                Interpolation::Quintic => JointSpline::Quintic(MinJerk::new(t, y, nv).map_err(|why| c.err(f, "", why))?),
            })
        }
        TargetSpec::Kinded(KindedTarget::JointCsv(cs)) => {
            let text = csv_text.ok_or_else(|| c.err("target.file", &cs.file, "the CSV was not read"))?;
            let (t, y) = parse_joint_csv(text, &cs.file, model, q_init.as_deref()).map_err(|why| c.err("target.file", &cs.file, why))?;
            Target::Joint(JointSpline::Cubic(CubicSpline::at_rest(t, y, nv).map_err(|why| c.err("target.file", &cs.file, why))?))
        }
        TargetSpec::Kinded(KindedTarget::Cartesian(cs)) => {
            let path = build_path(c, &cs.path)?;
            let iks = &cs.ik;
            let posture = match (&iks.posture, &q_init) {
                (Some(p), _) => {
                    if p.len() != nv {
                        return Err(c.err("target.ik.posture", format!("an array of {}", p.len()), format!("needs one angle per joint ({nv})")));
                    }
                    for (j, &x) in p.iter().enumerate() {
                        c.number(&format!("target.ik.posture[{j}]"), x, |_| true, "")?;
                    }
                    p.clone()
                }
                (None, Some(q0)) => q0.clone(),
                (None, None) => return Err(c.err("target.ik.posture", "", "is needed when initial.q is \"from-target\" (the IK's start and null-space posture)")),
            };
            let mut active = vec![iks.joints.is_none(); nv];
            for (k, name) in iks.joints.iter().flatten().enumerate() {
                let j = c.dof(&format!("target.ik.joints[{k}]"), model, name)?;
                if active[j] {
                    return Err(c.err(format!("target.ik.joints[{k}]"), name, "is listed twice"));
                }
                active[j] = true;
            }
            let mut contacts = Vec::with_capacity(iks.keep_contacts.len());
            for (k, name) in iks.keep_contacts.iter().enumerate() {
                let f = format!("target.ik.keep_contacts[{k}]");
                let Some((i, cspec)) = spec.contacts.iter().enumerate().find(|(_, x)| &x.name == name) else {
                    return Err(c.err(f, name, format!("no contact of that name (contacts: {})", names(spec.contacts.iter().map(|x| &x.name)))));
                };
                let point = c.point(&format!("contacts[{i}].point"), model, &cspec.point)?;
                let n = c.vec3(&format!("contacts[{i}].plane.normal"), cspec.plane.normal)?;
                if !(n.norm() > 1e-12) {
                    return Err(c.err(format!("contacts[{i}].plane.normal"), format!("{:?}", cspec.plane.normal), "must be non-zero"));
                }
                let offset = c.number(&format!("contacts[{i}].plane.offset"), cspec.plane.offset, |_| true, "")?;
                contacts.push(PointOnPlane { name: name.clone(), point, normal_world: nalgebra::Unit::new_normalize(n), offset });
            }
            let orientation = match &cs.orientation {
                Some(o) => {
                    let rpy = c.vec3("target.orientation.rpy", o.rpy)?;
                    Some((hand_frame_rotation(spec, model), UnitQuaternion::from_euler_angles(rpy.x, rpy.y, rpy.z)))
                }
                None => None,
            };
            let step = match iks.grid_step {
                Some(h) => c.number("target.ik.grid_step", h, |h| h > 0.0 && h <= duration, "must be > 0 s and at most the duration")?,
                None => DEFAULT_GRID_STEP.min(duration / 2.0),
            };
            if duration / step + 3.0 > MAX_KNOTS as f64 || (duration / step + 3.0) * model.nv as f64 > MAX_TARGET_VALUES as f64 {
                let knots = (duration / step + 3.0).min(MAX_KNOTS as f64 + 1.0);
                return Err(c.err(
                    "target.ik.grid_step",
                    step,
                    format!("gives {knots:.0} knots of {} joints over duration = {duration} s, more than {MAX_KNOTS} knots or {MAX_TARGET_VALUES} values (crate::limits::MAX_TARGET_VALUES); use a larger step", model.nv),
                ));
            }
            let ik = GeneralIk { hand: *hand, orientation, contacts, active, posture };
            let start = q_init.clone().unwrap_or_else(|| ik.posture.clone());
            let (q, stats) = track(&ik, model, &path, &start, duration, step).map_err(|e| {
                c.err(
                    "target.path",
                    format!("t = {:.4} s", e.t),
                    format!(
                        "the general IK cannot follow the path there: task residual {:.3e} m after {} iterations (the path leaves the workspace, or a joint limit or a kept contact stops the arm)",
                        e.stats.residual, e.stats.iterations
                    ),
                )
            })?;
            if stats.between_knots > MAX_BETWEEN_KNOTS {
                return Err(c.err("target.ik.grid_step", step, format!("the joint-space spline misses the path by {:.3e} m between knots (more than {MAX_BETWEEN_KNOTS:e} m): use a smaller step", stats.between_knots)));
            }
            Target::Cartesian { path, q, stats }
        }
    };
    let q0 = match q_init {
        Some(q) => q,
        None => {
            let (mut q, mut qd, mut qdd) = (vec![0.0; nv], vec![0.0; nv], vec![0.0; nv]);
            let mut scratch = TargetScratch::new(model);
            target.eval(0.0, model, hand, &mut scratch, &mut q, &mut qd, Some(&mut qdd)).map_err(|why| c.err("initial.q", "\"from-target\"", why))?;
            q
        }
    };
    Ok((target, q0))
}

/// The rotation of the hand's link frame in its body (identity for a frame that is the body's).
fn hand_frame_rotation(spec: &SceneSpec, model: &Model) -> UnitQuaternion<f64> {
    let link = match (&spec.hand.link, &spec.hand.joint) {
        (Some(l), _) => Some(l.clone()),
        (None, Some(j)) => model.urdf_joints.iter().find(|u| &u.name == j).map(|u| u.child_link.clone()),
        _ => None,
    };
    link.and_then(|l| model.frame(&l).map(|f| f.x_body_frame.rotation)).unwrap_or_else(UnitQuaternion::identity)
}

fn build_path(c: &Ctx, p: &PathSpec) -> Result<CartesianPath, SceneError> {
    let f = "target.path";
    let points = |ps: &PointsSpec, min: usize| -> Result<(), SceneError> {
        if ps.points.len() < min {
            return Err(c.err(format!("{f}.points"), format!("{} points", ps.points.len()), format!("needs at least {min}")));
        }
        if ps.times.len() != ps.points.len() {
            return Err(c.err(format!("{f}.times"), format!("{} times", ps.times.len()), format!("needs one time per point ({})", ps.points.len())));
        }
        for (k, p) in ps.points.iter().enumerate() {
            c.vec3(&format!("{f}.points[{k}]"), *p)?;
        }
        for (k, &t) in ps.times.iter().enumerate() {
            c.number(&format!("{f}.times[{k}]"), t, |_| true, "")?;
            if k > 0 && t <= ps.times[k - 1] {
                return Err(c.err(format!("{f}.times[{k}]"), t, format!("must be after times[{}] = {} s", k - 1, ps.times[k - 1])));
            }
        }
        Ok(())
    };
    Ok(match p {
        PathSpec::Circle(cs) => {
            let center = c.vec3(&format!("{f}.center"), cs.center)?;
            let normal = c.vec3(&format!("{f}.normal"), cs.normal)?;
            if !(normal.norm() > 1e-12) {
                return Err(c.err(format!("{f}.normal"), format!("{:?}", cs.normal), "must be non-zero"));
            }
            let zero_axis = match cs.zero_axis {
                Some(z) => Some(c.vec3(&format!("{f}.zero_axis"), z)?),
                None => None,
            };
            let radius = c.number(&format!("{f}.radius"), cs.radius, positive, "must be > 0 m")?;
            let period = c.number(&format!("{f}.period"), cs.period, positive, "must be > 0 s")?;
            let phase = c.number(&format!("{f}.phase"), cs.phase, |_| true, "")?;
            let dir = if cs.direction == Direction::CounterClockwise { 1.0 } else { -1.0 };
            let circle = CirclePath::new(center, normal, zero_axis, radius, period, phase, dir).map_err(|why| {
                let (field, value) = if why.starts_with("zero_axis") { ("zero_axis", format!("{:?}", cs.zero_axis.unwrap_or_default())) } else { ("normal", format!("{:?}", cs.normal)) };
                c.err(format!("{f}.{field}"), value, why.split(": ").nth(1).unwrap_or(&why).to_string())
            })?;
            CartesianPath::Circle(circle)
        }
        PathSpec::Lines(ps) => {
            points(ps, 2)?;
            CartesianPath::lines(&ps.points, &ps.times).map_err(|why| c.err(f, "", why))?
        }
        PathSpec::Waypoints(ps) => {
            points(ps, 2)?;
            CartesianPath::waypoints(&ps.points, &ps.times).map_err(|why| c.err(f, "", why))?
        }
    })
}

/// The samples of a joint CSV: header `t,<joint names in any order>`, then one row of numbers
/// per time (strictly increasing). Joints not in the header hold their `initial.q` angle.
/// Returns the times and the knot-major angles (nv per row). Errors name line and column
/// (both from 1; the column counts characters).
pub fn parse_joint_csv(text: &str, file: &str, model: &Model, q_init: Option<&[f64]>) -> Result<(Vec<f64>, Vec<f64>), String> {
    let nv = model.nv;
    let at = |line: usize, col: usize, why: String| format!("{file}, line {line}, column {col}: {why}");
    // the fields of a line with their 1-based start columns
    let fields = |l: &str| -> Vec<(usize, String)> {
        let mut out = Vec::new();
        let mut col = 1;
        for f in l.split(',') {
            let lead = f.chars().take_while(|ch| ch.is_whitespace()).count();
            out.push((col + lead, f.trim().to_string()));
            col += f.chars().count() + 1;
        }
        out
    };
    let mut lines = text.lines().enumerate().map(|(i, l)| (i + 1, l.trim_end_matches('\r'))).filter(|(_, l)| !l.trim().is_empty());
    let Some((hl, header)) = lines.next() else {
        return Err("the file is empty: it needs a header `t,<joint names>` and at least one row".into());
    };
    let head = fields(header);
    if head[0].1 != "t" {
        return Err(at(hl, head[0].0, format!("the first column must be `t` (s), found `{}`", head[0].1)));
    }
    let mut dofs = Vec::with_capacity(head.len() - 1);
    for (col, name) in &head[1..] {
        let Some(j) = model.dof_of_joint(name) else {
            return Err(at(hl, *col, format!("`{name}` is not a movable joint of the URDF (joints: {})", model.joint_names().join(", "))));
        };
        if dofs.contains(&j) {
            return Err(at(hl, *col, format!("joint `{name}` is listed twice")));
        }
        dofs.push(j);
    }
    let base = match q_init {
        Some(q) => q.to_vec(),
        None if dofs.len() == nv => vec![0.0; nv],
        None => {
            let missing: Vec<String> = (0..nv).filter(|j| !dofs.contains(j)).map(|j| model.bodies[j].joint.clone()).collect();
            return Err(at(hl, 1, format!("with initial.q \"from-target\" every joint needs a column; missing: {}", missing.join(", "))));
        }
    };
    let (mut t, mut y) = (Vec::new(), Vec::new());
    for (ln, line) in lines {
        let row = fields(line);
        if row.len() != head.len() {
            return Err(at(ln, 1, format!("{} fields, the header has {}", row.len(), head.len())));
        }
        let mut vals = Vec::with_capacity(row.len());
        for (col, s) in &row {
            match s.parse::<f64>() {
                Ok(x) if x.is_finite() => vals.push(x),
                _ => return Err(at(ln, *col, format!("`{s}` is not a finite number"))),
            }
        }
        if let Some(&prev) = t.last() {
            if vals[0] <= prev {
                return Err(at(ln, row[0].0, format!("t = {} s is not after the previous row's t = {prev} s", vals[0])));
            }
        }
        if (t.len() + 1) * nv > MAX_TARGET_VALUES {
            return Err(at(ln, 1, format!("more than {} rows of {nv} joints: a joint target holds at most {MAX_TARGET_VALUES} values (crate::limits::MAX_TARGET_VALUES); thin the file", t.len())));
        }
        t.push(vals[0]);
        let mut q = base.clone();
        for (k, &j) in dofs.iter().enumerate() {
            q[j] = vals[k + 1];
        }
        y.extend_from_slice(&q);
    }
    if t.is_empty() {
        return Err(at(hl, 1, "a header but no rows: at least one row of samples is needed".into()));
    }
    Ok((t, y))
}
