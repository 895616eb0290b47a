//! One recording, read for drawing: the frame tree of `/tf` as world poses per sample, the URDF's
//! visuals, the contact planes and points, and the typed signals (`/motors`, `/energy`,
//! `/constraints` or `/contacts`, `/hand`, `/contact_events`).
//!
//! Everything comes through the typed reader of `schemas` ([`Recording::read_sized`], the
//! metadata records); the contact points and planes come from the `contacts` record when the
//! recording has one, and from the scene the recording embeds (its `contacts[].point` and
//! `.plane`, the scene's own keys) for the points and for the planes of a run without an active
//! contact (the paper's no-elbow run still shows the table its scene defines).

use std::collections::BTreeMap;

use schemas::{
    RunResult, RunStatus, ArraySizes, ConstraintState, ContactEventMsg, ContactState, ContactsRecord, EnergyState, HandState, MotorState, Recording,
    Transforms,
};

use super::pose::Pose;
use super::urdf::{self, Visuals};
use crate::Error;

/// A contact plane `n · x = d` (world frame).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Plane {
    pub normal: [f64; 3],
    pub offset_m: f64,
}

/// Where a contact acts: a point fixed in a link (the child link of the scene's `point.joint`,
/// or its `point.link`), at `offset_m` in that link's frame.
#[derive(Debug, Clone, PartialEq)]
pub struct ContactPoint {
    pub name: String,
    /// `None` when the recording does not say (no scene, or no `/tf`): no 3D marker then.
    pub link: Option<String>,
    pub offset_m: [f64; 3],
    /// `None` when neither the `contacts` record nor the scene gives it: no table is drawn for
    /// it, and its force arrow points along +z.
    pub plane: Option<Plane>,
    /// Tangent basis of the friction forces (world frame), from the `contacts` record.
    pub tangents: Option<([f64; 3], [f64; 3])>,
    /// Friction coefficient μ, from the `contacts` record (unilateral and compliant contacts).
    pub friction: Option<f64>,
}

/// A frame of the `/tf` tree and its poses.
#[derive(Debug, Clone)]
pub struct Frame {
    pub parent: String,
    /// Pose in the parent frame, per sample.
    pub in_parent: Vec<Pose>,
}

/// A recording, read for drawing.
pub struct Run {
    /// The run's name (metadata `run.run`), or the file stem.
    pub name: String,
    pub joints: Vec<String>,
    /// The run's active contacts, in array order.
    pub contacts: Vec<ContactPoint>,
    /// Planes of the scene's contacts that are not active in this run (drawn as the table too).
    pub other_planes: Vec<Plane>,
    /// The root of the `/tf` tree (`world`).
    pub root_frame: String,
    /// Frames in the order they first appear (parents before children).
    pub frames: Vec<(String, Frame)>,
    /// Times of the `/tf` samples, ns.
    pub tf_times_ns: Vec<i64>,
    pub visuals: Visuals,
    pub hand: Vec<(f64, HandState)>,
    pub motors: Vec<(f64, MotorState)>,
    pub energy: Vec<(f64, EnergyState)>,
    pub constraints: Vec<(f64, ConstraintState)>,
    /// `/contacts` (runs with a unilateral or compliant contact).
    pub contact_states: Option<Vec<(f64, ContactState)>>,
    pub events: Vec<(f64, ContactEventMsg)>,
    /// The run's status and reason (record `result`), when the recording has one.
    pub result: Option<RunResult>,
    /// What `/scene` says (the force scale, the tables, the scale bar), so that Rerun draws
    /// what Foxglove draws; the defaults for a recording without it.
    pub scene: schemas::markers::SceneRead,
}

fn bad(file: &str, detail: String) -> Error {
    Error::View { file: file.to_string(), detail }
}

/// Seconds -> ns on the timeline.
pub fn ns(t_s: f64) -> i64 {
    (t_s * 1e9).round() as i64
}

fn vec3(v: &serde_json::Value) -> Option<[f64; 3]> {
    let a = v.as_array()?;
    Some([a.first()?.as_f64()?, a.get(1)?.as_f64()?, a.get(2)?.as_f64()?])
}

impl Run {
    /// Reads what is drawn from `rec` (`stem`: the file stem, the name of a run without a `run`
    /// record).
    pub fn read(rec: &Recording, stem: &str) -> Result<Run, Error> {
        let file = rec.source.clone();
        let desc = rec.run_opt()?;
        let (name, joints, active) = match desc {
            Some(d) => (d.run, d.joint_names, d.contacts),
            None => (stem.to_string(), Vec::new(), Vec::new()),
        };
        let sizes = ArraySizes { joints: joints.len(), contacts: active.len() };

        // geometry (a recording of another producer may have no URDF: no visuals then)
        let xml = rec.record_opt::<schemas::UrdfRecord>()?.map(|u| u.xml).unwrap_or_default();
        let visuals = urdf::visuals(&xml).map_err(|e| bad(&file, format!("metadata urdf: {e}")))?;
        let children = urdf::joint_children(&xml).map_err(|e| bad(&file, format!("metadata urdf: {e}")))?;

        // contacts: the scene says where (point) and on what (plane); the contacts record, when
        // present, gives the plane and the friction basis the recording used
        let scene: Option<serde_json::Value> = rec.scene().ok().and_then(|s| serde_json::from_str(&s.json).ok());
        let record: Option<ContactsRecord> = rec.record_opt()?;
        let scene_contacts: Vec<&serde_json::Value> =
            scene.as_ref().and_then(|s| s.get("contacts")).and_then(|c| c.as_array()).map(|a| a.iter().collect()).unwrap_or_default();
        let scene_plane = |c: &serde_json::Value| -> Option<Plane> {
            let p = c.get("plane")?;
            Some(Plane { normal: vec3(p.get("normal")?)?, offset_m: p.get("offset").and_then(|o| o.as_f64()).unwrap_or(0.0) })
        };
        let mut contacts = Vec::new();
        for cname in &active {
            let sc = scene_contacts.iter().find(|c| c.get("name").and_then(|n| n.as_str()) == Some(cname.as_str()));
            let info = record.as_ref().and_then(|r| r.contact(cname));
            let plane = match (info, sc.and_then(|c| scene_plane(c))) {
                (Some(i), _) => Some(Plane { normal: i.normal, offset_m: i.offset }),
                (None, p) => p,
            };
            let point = sc.and_then(|c| c.get("point"));
            let link = match (
                point.and_then(|p| p.get("joint")).and_then(|j| j.as_str()),
                point.and_then(|p| p.get("link")).and_then(|l| l.as_str()),
            ) {
                (Some(j), _) => Some(
                    children
                        .get(j)
                        .cloned()
                        .ok_or_else(|| bad(&file, format!("contact {cname:?}: point.joint = {j:?} is no joint of the URDF")))?,
                ),
                (None, Some(l)) => Some(l.to_string()),
                (None, None) => None,
            };
            let offset_m = point.and_then(|p| p.get("offset")).and_then(vec3).unwrap_or([0.0; 3]);
            contacts.push(ContactPoint { name: cname.clone(), link, offset_m, plane, tangents: info.map(|i| (i.t1, i.t2)), friction: info.and_then(|i| i.friction) });
        }
        let mut other_planes = Vec::new();
        for c in &scene_contacts {
            if let Some(p) = scene_plane(c) {
                if !contacts.iter().any(|k| k.plane == Some(p)) && !other_planes.contains(&p) {
                    other_planes.push(p);
                }
            }
        }

        // the frame tree (none without /tf)
        let tf: Vec<(f64, Transforms)> = match rec.channel(schemas::topics::TF) {
            Some(_) => rec.read()?,
            None => Vec::new(),
        };
        let mut frames: Vec<(String, Frame)> = Vec::new();
        let mut index: BTreeMap<String, usize> = BTreeMap::new();
        let mut tf_times_ns = Vec::with_capacity(tf.len());
        for (k, (t, msg)) in tf.iter().enumerate() {
            tf_times_ns.push(ns(*t));
            for e in &msg.transforms {
                let pose = Pose {
                    translation: [e.translation.x, e.translation.y, e.translation.z],
                    rotation: [e.rotation.x, e.rotation.y, e.rotation.z, e.rotation.w],
                };
                let i = *index.entry(e.child_frame_id.clone()).or_insert_with(|| {
                    frames.push((e.child_frame_id.clone(), Frame { parent: e.parent_frame_id.clone(), in_parent: Vec::new() }));
                    frames.len() - 1
                });
                let f = &mut frames[i].1;
                if f.parent != e.parent_frame_id {
                    return Err(bad(&file, format!("/tf message #{k}: frame {:?} changes parent ({:?} -> {:?})", e.child_frame_id, f.parent, e.parent_frame_id)));
                }
                // a frame missing from a message keeps its last pose
                while f.in_parent.len() < k {
                    let last = f.in_parent.last().copied().unwrap_or(Pose::IDENTITY);
                    f.in_parent.push(last);
                }
                f.in_parent.push(pose);
            }
        }
        for (_, f) in &mut frames {
            while f.in_parent.len() < tf.len() {
                let last = f.in_parent.last().copied().unwrap_or(Pose::IDENTITY);
                f.in_parent.push(last);
            }
        }
        let root_frame = match frames.iter().map(|(_, f)| f.parent.clone()).find(|p| !index.contains_key(p)) {
            Some(root) => root,
            None if frames.is_empty() => "world".to_string(),
            None => return Err(bad(&file, "/tf: every frame has a parent in /tf (a cycle, no root frame)".into())),
        };
        for c in &mut contacts {
            match &c.link {
                Some(link) if !frames.is_empty() && !index.contains_key(link) => {
                    return Err(bad(&file, format!("contact {:?}: link {link:?} has no transform in /tf", c.name)));
                }
                Some(_) if frames.is_empty() => c.link = None,
                _ => {}
            }
        }

        let contact_states = match rec.channel(schemas::topics::CONTACTS) {
            Some(_) => Some(rec.read_sized::<ContactState>(sizes)?),
            None => None,
        };
        let events = match rec.channel(schemas::topics::CONTACT_EVENTS) {
            Some(_) => rec.read::<ContactEventMsg>()?,
            None => Vec::new(),
        };
        // a run that failed early may have no samples (t = 0: no topic at all): drawn empty
        let result = rec.result()?;
        let failed = result.as_ref().is_some_and(|r| r.status == RunStatus::Failed);
        let absent = |topic: &str| failed && rec.channel(topic).is_none();
        Ok(Run {
            name,
            joints,
            contacts,
            other_planes,
            root_frame,
            frames,
            tf_times_ns,
            visuals,
            hand: if absent(schemas::topics::HAND) { Vec::new() } else { rec.read()? },
            motors: if absent(schemas::topics::MOTORS) { Vec::new() } else { rec.read_sized(sizes)? },
            energy: if absent(schemas::topics::ENERGY) { Vec::new() } else { rec.read_sized(sizes)? },
            constraints: if absent(schemas::topics::CONSTRAINTS) { Vec::new() } else { rec.read_sized(sizes)? },
            contact_states,
            events,
            result,
            scene: schemas::markers::SceneRead::from_recording(rec),
        })
    }

    /// The world pose of every frame at sample `k` (the root is the identity).
    pub fn world_poses(&self, k: usize) -> BTreeMap<&str, Pose> {
        let mut out: BTreeMap<&str, Pose> = BTreeMap::new();
        out.insert(self.root_frame.as_str(), Pose::IDENTITY);
        // parents come first in `frames` unless a frame appeared before its parent: repeat
        for _ in 0..self.frames.len() {
            let before = out.len();
            for (name, f) in &self.frames {
                if out.contains_key(name.as_str()) {
                    continue;
                }
                if let Some(parent) = out.get(f.parent.as_str()).copied() {
                    out.insert(name.as_str(), parent.compose(&f.in_parent[k]));
                }
            }
            if out.len() == before {
                break;
            }
        }
        out
    }

    /// The entity path of `frame` below `root` (its chain of parents): `root/base/link1/…`.
    pub fn frame_path(&self, frame: &str, root: &str) -> String {
        let mut chain = Vec::new();
        let mut f = frame;
        while f != self.root_frame {
            chain.push(f);
            match self.frames.iter().find(|(n, _)| n == f) {
                Some((_, fr)) => f = fr.parent.as_str(),
                None => break,
            }
            if chain.len() > self.frames.len() {
                break;
            }
        }
        chain.reverse();
        let mut p = root.to_string();
        for c in chain {
            p.push('/');
            p.push_str(&escape(c));
        }
        p
    }
}

/// A name as one entity path part (Rerun's path grammar: letters, digits, `-`, `_`, `.`; other
/// characters escaped with `\`).
pub fn escape(name: &str) -> String {
    let mut s = String::with_capacity(name.len());
    for ch in name.chars() {
        if ch.is_ascii_alphanumeric() || matches!(ch, '-' | '_' | '.') {
            s.push(ch);
        } else {
            s.push('\\');
            s.push(ch);
        }
    }
    s
}
