//! One recording, read for drawing: the frame tree of `/tf` as world poses per sample, the URDF's
//! visuals, the contact planes and points, and the typed signals (`/motors`, `/energy`,
//! `/constraints` or `/contacts`, `/hand`, `/contact_events`).
//!
//! Read streamed, never whole (issue 29: memory bounded by the work, not the file): [`Run::survey`]
//! reads the metadata and, in a streamed pass with O(1) memory per series, what needs the whole
//! run ([`Whole`]: bounds, force scale, y ranges, the hand paths decimated); the samples come
//! later, one time window at a time (`super::window`), into the same [`Run`]. Messages are
//! decoded by the typed reader of `schemas` (its array checks, the metadata records); a `/tf`
//! transform from a frame to itself (a URDF whose root link is named `world`, as UR5's and Z1's
//! of example-robot-data, under the recording's `world` → root) is left out of the tree. The
//! contact points and planes come from the `contacts` record when the
//! recording has one, and from the scene the recording embeds (its `contacts[].point` and
//! `.plane`, the scene's own keys) for the points and for the planes of a run without an active
//! contact (the paper's no-elbow run still shows the table its scene defines).

use std::collections::BTreeMap;
use std::path::Path;

use schemas::{
    ArraySizes, ConstraintState, ContactEventMsg, ContactState, ContactsRecord, EnergyState, HandState, MotorState, Recording, RunResult, RunStatus,
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
    /// Its shape on its link, from the `contacts` record (recordings since issue 27): where
    /// it touches (`ContactShapeInfo::lowest_point`) and what is drawn on the link.
    pub shape: Option<schemas::ContactShapeInfo>,
}

/// A frame of the `/tf` tree and its poses.
#[derive(Debug, Clone)]
pub struct Frame {
    pub parent: String,
    /// Pose in the parent frame, per sample of the window.
    pub in_parent: Vec<Pose>,
}

/// A recording, read for drawing.
#[derive(Debug, Clone)]
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
    /// Frames in the order they first appear (parents before children); their poses are those
    /// of the time window being drawn.
    pub frames: Vec<(String, Frame)>,
    /// Times of the window's `/tf` samples, ns (the samples below are the window's too).
    pub tf_times_ns: Vec<i64>,
    pub visuals: Visuals,
    /// Every link's visuals and collisions, meshes too (drawn by [`super::mesh`]).
    pub links: urdf::Links,
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
    /// what Foxglove draws; the defaults for a recording without it ([`Run::survey`]).
    pub scene: schemas::markers::SceneRead,
    /// What needs the whole run ([`Run::survey`]).
    pub whole: Whole,
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

/// What needs the whole run, gathered by [`Run::survey`] in one streamed pass with O(1)
/// memory per series (the hand paths are kept decimated to at most [`MAX_PATH_POINTS`]): the
/// views' cameras, the table's size, the arrows' scale and the plots' y ranges are those of the
/// whole run, whichever time window is being drawn.
#[derive(Debug, Clone, PartialEq)]
pub struct Whole {
    /// Bounds of the arm (every frame origin at about 200 samples, and the hand), m (world).
    pub arm_min: [f64; 3],
    pub arm_max: [f64; 3],
    /// Bounds of the hand path (actual and desired), m (world).
    pub hand_min: [f64; 3],
    pub hand_max: [f64; 3],
    /// The arm's base (the first frame below the root), at t = 0.
    pub base: [f64; 3],
    /// The desired and the actual hand positions (world), every sample or evenly decimated,
    /// and the times of the actual ones, ns (the trail up to the current time).
    pub target_path: Vec<[f64; 3]>,
    pub hand_trail: Vec<[f64; 3]>,
    pub hand_trail_t: Vec<i64>,
    /// [`range_after_transient`] of the motor currents and voltages.
    pub current_range: Option<[f64; 2]>,
    pub voltage_range: Option<[f64; 2]>,
    /// The first `/motors` message records voltages; every one records one per joint.
    pub has_voltage: bool,
    pub voltage_every_joint: bool,
    /// The run records `/contacts` (modes and friction), `/contact_events` messages.
    pub has_contact_states: bool,
    pub has_events: bool,
    /// Messages per drawn topic.
    pub counts: BTreeMap<String, usize>,
    /// Where each plot's samples lie (the legends' corners; an empty one: no plot).
    pub envelopes: Envelopes,
    /// The largest |balance residual| of `/energy`, J (the residual plot's range).
    pub residual_max_abs: f64,
}

impl Default for Whole {
    fn default() -> Self {
        Whole {
            arm_min: [f64::INFINITY; 3],
            arm_max: [f64::NEG_INFINITY; 3],
            hand_min: [f64::INFINITY; 3],
            hand_max: [f64::NEG_INFINITY; 3],
            base: [0.0; 3],
            target_path: Vec::new(),
            hand_trail: Vec::new(),
            hand_trail_t: Vec::new(),
            current_range: None,
            voltage_range: None,
            has_voltage: false,
            voltage_every_joint: true,
            has_contact_states: false,
            has_events: false,
            counts: BTreeMap::new(),
            envelopes: Envelopes::default(),
            residual_max_abs: 0.0,
        }
    }
}

/// Columns of an [`Envelope`] over the run's time span.
pub const ENVELOPE_COLUMNS: usize = 60;

/// Where the samples of a plot lie, gathered as they stream by in O(1) memory: over
/// [`ENVELOPE_COLUMNS`] equal columns of the time span `[t0, t_end]` (a sample outside goes in
/// the nearest column), the lowest and highest value of every series in each column. Whether
/// a sample of the plot lies in a band at the top or bottom of the y range is then exact per
/// column (`layout::legend_corner`); no samples at all means the plot has no data.
#[derive(Debug, Clone, PartialEq)]
pub struct Envelope {
    t0: f64,
    t_end: f64,
    /// Per column: `[min, max]` (`[inf, -inf]` for an empty column).
    pub columns: Vec<[f64; 2]>,
    /// Finite samples pushed.
    pub samples: usize,
}

impl Default for Envelope {
    fn default() -> Self {
        Envelope::new(0.0, 0.0)
    }
}

impl Envelope {
    pub fn new(t0: f64, t_end: f64) -> Self {
        Envelope { t0, t_end, columns: vec![[f64::INFINITY, f64::NEG_INFINITY]; ENVELOPE_COLUMNS], samples: 0 }
    }

    /// The values of the series at time `t`, s (non-finite ones are left out).
    pub fn push(&mut self, t: f64, values: impl IntoIterator<Item = f64>) {
        let span = self.t_end - self.t0;
        let x = if span > 0.0 { ((t - self.t0) / span).clamp(0.0, 1.0) } else { 0.0 };
        let k = ((x * ENVELOPE_COLUMNS as f64) as usize).min(ENVELOPE_COLUMNS - 1);
        let c = &mut self.columns[k];
        for y in values.into_iter().filter(|y| y.is_finite()) {
            *c = [c[0].min(y), c[1].max(y)];
            self.samples += 1;
        }
    }

    pub fn is_empty(&self) -> bool {
        self.samples == 0
    }

    /// The lowest and highest value, `None` when empty.
    pub fn range(&self) -> Option<[f64; 2]> {
        (!self.is_empty()).then(|| self.columns.iter().fold([f64::INFINITY, f64::NEG_INFINITY], |[a, b], c| [a.min(c[0]), b.max(c[1])]))
    }
}

/// The [`Envelope`] of each plot of a run (`layout::plots`).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Envelopes {
    pub current: Envelope,
    pub voltage: Envelope,
    pub normal_force: Envelope,
    /// `|v_t|` of `/contacts`.
    pub slip_speed: Envelope,
    /// `|f_t| / (μ f_n)` of the samples with `f_n > 0` of the contacts with `μ > 0`.
    pub friction_ratio: Envelope,
    pub friction_force: Envelope,
    pub contact_mode: Envelope,
    pub electric_energy: Envelope,
    pub link_work: Envelope,
}

/// The most points of the static target path and hand trail: a longer run is decimated evenly
/// (every k-th sample and the last), so that a 300 s run at 1 kHz costs no more than 40 000
/// points (the viewer cannot show more on a screen either).
pub const MAX_PATH_POINTS: usize = 20_000;

/// The topics drawn (read by [`Run::survey`] and by the windowed encoder).
pub const DRAWN: [&str; 7] = [
    schemas::topics::TF,
    schemas::topics::HAND,
    schemas::topics::MOTORS,
    schemas::topics::ENERGY,
    schemas::topics::CONSTRAINTS,
    schemas::topics::CONTACTS,
    schemas::topics::CONTACT_EVENTS,
];

/// The topics [`Run::survey`] reads: the drawn ones and `/scene` (the force scale, the tables
/// and the scale bar Foxglove draws: one small message).
pub const SURVEYED: [&str; 8] = {
    let mut topics = [schemas::topics::SCENE; 8];
    let mut k = 0;
    while k < DRAWN.len() {
        topics[k] = DRAWN[k];
        k += 1;
    }
    topics
};

pub fn grow(min: &mut [f64; 3], max: &mut [f64; 3], p: [f64; 3]) {
    for i in 0..3 {
        min[i] = min[i].min(p[i]);
        max[i] = max[i].max(p[i]);
    }
}

/// [`range_after_transient`] computed as the samples stream by: the skip time is known
/// beforehand (from the first and last time of the series), and only four numbers are kept.
#[derive(Debug, Clone, Copy)]
pub struct RangeAfter {
    skip_s: f64,
    all: [f64; 2],
    after: [f64; 2],
    any: bool,
}

impl RangeAfter {
    /// For samples from `t0` to `t_end`, s.
    pub fn new(t0: f64, t_end: f64) -> Self {
        RangeAfter { skip_s: t0 + 0.05 * (t_end - t0), all: [f64::INFINITY, f64::NEG_INFINITY], after: [f64::INFINITY, f64::NEG_INFINITY], any: false }
    }

    pub fn push(&mut self, t: f64, values: &[f64]) {
        self.any = true;
        for &x in values {
            self.all = [self.all[0].min(x), self.all[1].max(x)];
            if t >= self.skip_s {
                self.after = [self.after[0].min(x), self.after[1].max(x)];
            }
        }
    }

    /// The range of [`range_after_transient`].
    pub fn finish(&self) -> Option<[f64; 2]> {
        let ([lo_all, hi_all], [lo, hi]) = (self.all, self.after);
        if !self.any || !lo.is_finite() || !hi.is_finite() || hi_all - lo_all <= 3.0 * (hi - lo) {
            return None;
        }
        let pad = 0.1 * (hi - lo).max(1e-9);
        Some([lo - pad, hi + pad])
    }
}

/// A y range that leaves out a start-up transient: the range of the samples after the first
/// 5 % of the run, padded by 10 %, when the whole range is more than 3 times wider (else
/// `None`: the viewer fits every sample).
pub fn range_after_transient(samples: &[(f64, Vec<f64>)]) -> Option<[f64; 2]> {
    let mut r = RangeAfter::new(samples.first()?.0, samples.last()?.0);
    for (t, v) in samples {
        r.push(*t, v);
    }
    r.finish()
}

/// The `/tf` tree as it streams by: frames in the order they first appear (parents before
/// children in our recordings), each frame's parent and its latest pose in the parent.
#[derive(Debug, Clone, Default)]
pub struct FrameTree {
    pub frames: Vec<(String, Frame)>,
    index: BTreeMap<String, usize>,
    /// The latest pose of each frame in its parent (identity before its first transform).
    pub latest: Vec<Pose>,
    /// Messages taken.
    pub messages: usize,
}

impl FrameTree {
    /// Takes `/tf` message #`k` (`self.messages`): a new frame is appended, a known one must keep
    /// its parent. A frame whose parent is itself (a URDF whose root link has the world's name,
    /// `world` → `world`) is no frame of the tree: it is left out.
    pub fn take(&mut self, file: &str, msg: &Transforms) -> Result<(), Error> {
        let k = self.messages;
        for e in &msg.transforms {
            if e.child_frame_id == e.parent_frame_id {
                continue;
            }
            let pose = Pose {
                translation: [e.translation.x, e.translation.y, e.translation.z],
                rotation: [e.rotation.x, e.rotation.y, e.rotation.z, e.rotation.w],
            };
            let i = match self.index.get(&e.child_frame_id) {
                Some(&i) => i,
                None => {
                    self.frames.push((e.child_frame_id.clone(), Frame { parent: e.parent_frame_id.clone(), in_parent: Vec::new() }));
                    self.latest.push(Pose::IDENTITY);
                    self.index.insert(e.child_frame_id.clone(), self.frames.len() - 1);
                    self.frames.len() - 1
                }
            };
            let f = &self.frames[i].1;
            if f.parent != e.parent_frame_id {
                return Err(bad(file, format!("/tf message #{k}: frame {:?} changes parent ({:?} -> {:?})", e.child_frame_id, f.parent, e.parent_frame_id)));
            }
            self.latest[i] = pose;
        }
        self.messages += 1;
        Ok(())
    }

    pub fn contains(&self, frame: &str) -> bool {
        self.index.contains_key(frame)
    }

    /// The root: the first parent that is no frame of the tree (`world` for an empty tree).
    pub fn root(&self, file: &str) -> Result<String, Error> {
        match self.frames.iter().map(|(_, f)| f.parent.clone()).find(|p| !self.index.contains_key(p)) {
            Some(root) => Ok(root),
            None if self.frames.is_empty() => Ok("world".to_string()),
            None => Err(bad(file, "/tf: every frame has a parent in /tf (a cycle, no root frame)".into())),
        }
    }
}

/// The world pose of every frame of `frames` below `root` (the identity), each frame's pose in
/// its parent given by `pose(i)`.
pub fn world_poses<'a>(root: &'a str, frames: &'a [(String, Frame)], pose: impl Fn(usize) -> Pose) -> BTreeMap<&'a str, Pose> {
    let mut out: BTreeMap<&str, Pose> = BTreeMap::new();
    out.insert(root, Pose::IDENTITY);
    // parents come first in `frames` unless a frame appeared before its parent: repeat
    for _ in 0..frames.len() {
        let before = out.len();
        for (i, (name, f)) in frames.iter().enumerate() {
            if out.contains_key(name.as_str()) {
                continue;
            }
            if let Some(parent) = out.get(f.parent.as_str()).copied() {
                out.insert(name.as_str(), parent.compose(&pose(i)));
            }
        }
        if out.len() == before {
            break;
        }
    }
    out
}

/// Pass 1 of [`Run::survey`]: the first and last time of `/motors` (the skip time of the y
/// ranges).
#[derive(Default)]
struct MotorTimes(Option<(f64, f64)>);

impl schemas::Visitor for MotorTimes {
    fn message(&mut self, m: schemas::DecodedMessage<'_>) -> Result<(), schemas::Error> {
        let t = m.t_s();
        self.0 = Some(self.0.map_or((t, t), |(t0, _)| (t0, t)));
        Ok(())
    }
}

/// Pass 2 of [`Run::survey`]: everything [`Whole`] holds, the frame tree and the checks of
/// every message (array sizes), as the samples stream by.
struct Survey<'a> {
    file: &'a str,
    sizes: ArraySizes,
    tree: FrameTree,
    whole: Whole,
    /// Samples of `/tf` and `/hand` (from the file's counts).
    n_tf: usize,
    n_hand: usize,
    force_topic: &'static str,
    hand_k: usize,
    motors: Option<(RangeAfter, RangeAfter)>,
    motor_times: Option<(f64, f64)>,
    joints: usize,
    /// The friction coefficient μ of each active contact (0: none recorded).
    friction: Vec<f64>,
    /// The first `/scene` message, read.
    scene: Option<schemas::markers::SceneRead>,
    /// The error that stopped the reading (returned instead of the reader's).
    error: Option<Error>,
}

/// Keeps `e` in `slot` and gives the reader an error that stops it (the caller returns `e`).
pub fn stop(slot: &mut Option<Error>, e: Error) -> schemas::Error {
    let detail = e.to_string();
    *slot = Some(e);
    schemas::Error::Malformed { file: String::new(), detail }
}

/// An error of `analyze view` (`slot`) over the reader's (`read`).
pub fn first_error<T>(read: Result<T, schemas::Error>, slot: Option<Error>) -> Result<T, Error> {
    match (read, slot) {
        (_, Some(e)) => Err(e),
        (r, None) => Ok(r?),
    }
}

impl Survey<'_> {
    fn tf(&mut self, msg: &Transforms) -> Result<(), Error> {
        let k = self.tree.messages;
        self.tree.take(self.file, msg)?;
        let stride = (self.n_tf / 200).max(1);
        if k == 0 || k.is_multiple_of(stride) || k + 1 == self.n_tf {
            let root = self.tree.root(self.file).unwrap_or_else(|_| "world".into());
            let latest = &self.tree.latest;
            let poses = world_poses(&root, &self.tree.frames, |i| latest[i]);
            if k == 0 {
                if let Some((base, _)) = self.tree.frames.iter().find(|(_, f)| f.parent == root) {
                    self.whole.base = poses.get(base.as_str()).map_or([0.0; 3], |p| p.translation);
                }
            }
            if k.is_multiple_of(stride) || k + 1 == self.n_tf {
                for p in poses.values() {
                    grow(&mut self.whole.arm_min, &mut self.whole.arm_max, p.translation);
                }
            }
        }
        Ok(())
    }

    fn hand(&mut self, t: f64, h: &HandState) {
        let v3 = |v: &schemas::Vec3| [v.x, v.y, v.z];
        let (desired, actual) = (v3(&h.desired), v3(&h.actual));
        let w = &mut self.whole;
        for p in [desired, actual] {
            grow(&mut w.hand_min, &mut w.hand_max, p);
            grow(&mut w.arm_min, &mut w.arm_max, p);
        }
        let stride = self.n_hand.div_ceil(MAX_PATH_POINTS).max(1);
        if self.hand_k.is_multiple_of(stride) || self.hand_k + 1 == self.n_hand {
            w.target_path.push(desired);
            w.hand_trail.push(actual);
            w.hand_trail_t.push(ns(t));
        }
        self.hand_k += 1;
    }

    fn motors(&mut self, t: f64, m: &MotorState) {
        let (t0, t_end) = self.motor_times.unwrap_or((t, t));
        let (cur, volt) = self.motors.get_or_insert_with(|| (RangeAfter::new(t0, t_end), RangeAfter::new(t0, t_end)));
        if !cur.any {
            self.whole.has_voltage = !m.voltage.is_empty();
        }
        cur.push(t, &m.current);
        self.whole.envelopes.current.push(t, m.current.iter().copied());
        if self.whole.has_voltage {
            volt.push(t, &m.voltage);
            self.whole.envelopes.voltage.push(t, m.voltage.iter().copied());
        }
        self.whole.voltage_every_joint &= m.voltage.len() == self.joints;
    }

    /// One sample of `/contacts`: normal and friction forces, slip speeds, the friction use
    /// `|f_t| / (μ f_n)` where `f_n > 0` and `μ > 0`, the modes.
    fn contacts(&mut self, t: f64, s: &ContactState) {
        let e = &mut self.whole.envelopes;
        let norm = |a: &[f64], b: &[f64], c: usize| a.get(c).copied().unwrap_or(0.0).hypot(b.get(c).copied().unwrap_or(0.0));
        let n = s.normal_force.len();
        e.normal_force.push(t, s.normal_force.iter().copied());
        if !s.slip_velocity_t1.is_empty() {
            e.slip_speed.push(t, (0..n).map(|c| norm(&s.slip_velocity_t1, &s.slip_velocity_t2, c)));
        }
        if !s.friction_force_t1.is_empty() {
            e.friction_force.push(t, (0..n).map(|c| norm(&s.friction_force_t1, &s.friction_force_t2, c)));
            let ratio = (0..n).filter_map(|c| {
                let (mu, f_n) = (self.friction.get(c).copied().unwrap_or(0.0), s.normal_force[c]);
                (mu > 0.0 && f_n > 0.0).then(|| norm(&s.friction_force_t1, &s.friction_force_t2, c) / (mu * f_n))
            });
            e.friction_ratio.push(t, ratio);
        }
        e.contact_mode.push(t, s.mode.iter().map(|&m| f64::from(m)));
    }
}

impl schemas::Visitor for Survey<'_> {
    fn message(&mut self, m: schemas::DecodedMessage<'_>) -> Result<(), schemas::Error> {
        let sizes = Some(self.sizes);
        match m.topic {
            schemas::topics::TF => {
                let msg = m.decode_ref::<Transforms>(None)?;
                if let Err(e) = self.tf(&msg) {
                    return Err(stop(&mut self.error, e));
                }
            }
            schemas::topics::HAND => {
                let h = m.decode_ref::<HandState>(None)?;
                self.hand(m.t_s(), &h);
            }
            schemas::topics::MOTORS => {
                let s = m.decode_ref::<MotorState>(sizes)?;
                self.motors(m.t_s(), &s);
            }
            schemas::topics::ENERGY => {
                let e = m.decode_ref::<EnergyState>(sizes)?;
                let w = &mut self.whole;
                w.envelopes.electric_energy.push(m.t_s(), e.electric_energy.iter().copied());
                w.envelopes.link_work.push(m.t_s(), e.link_work.iter().copied());
                if e.balance_residual.is_finite() {
                    w.residual_max_abs = w.residual_max_abs.max(e.balance_residual.abs());
                }
            }
            schemas::topics::CONSTRAINTS => {
                let s = m.decode_ref::<ConstraintState>(sizes)?;
                if self.force_topic == schemas::topics::CONSTRAINTS {
                    self.whole.envelopes.normal_force.push(m.t_s(), s.normal_force.iter().copied());
                }
            }
            schemas::topics::CONTACTS => {
                let s = m.decode_ref::<ContactState>(sizes)?;
                self.contacts(m.t_s(), &s);
            }
            schemas::topics::CONTACT_EVENTS => {
                m.decode_ref::<ContactEventMsg>(None)?;
            }
            schemas::topics::SCENE if self.scene.is_none() => self.scene = Some(schemas::markers::SceneRead::from_decoded(&m)),
            _ => {}
        }
        Ok(())
    }

    fn typed(&self) -> bool {
        true
    }
}

impl Run {
    /// Reads what is drawn from the recording at `path` except its samples (`stem`: the file
    /// stem, the name of a run without a `run` record), and what needs the whole run
    /// ([`Whole`]), in two streamed passes: `/motors` alone for its first and last time, then
    /// every drawn topic. Memory: the file's metadata, the frame tree and O(1) per series.
    pub fn survey(path: &Path, stem: &str) -> Result<Run, Error> {
        let mut times = MotorTimes::default();
        let rec = schemas::stream_recording(path, Some(&[schemas::topics::MOTORS]), &mut times)?;
        let mut run = Run::describe(&rec, stem)?;
        let file = rec.source.clone();
        let count = |topic: &str| rec.channel(topic).map_or(0, |c| c.message_count);
        let has_contacts = rec.channel(schemas::topics::CONTACTS).is_some();
        let force_topic = if has_contacts { schemas::topics::CONTACTS } else { schemas::topics::CONSTRAINTS };
        // the topics every run has (a run that failed early may have none)
        let failed = run.result.as_ref().is_some_and(|r| r.status == RunStatus::Failed);
        for topic in [schemas::topics::HAND, schemas::topics::MOTORS, schemas::topics::ENERGY, schemas::topics::CONSTRAINTS] {
            if !failed && rec.channel(topic).is_none() {
                let available = rec.channels.iter().map(|c| c.topic.clone()).collect();
                return Err(schemas::Error::UnknownTopic { file: file.clone(), topic: topic.into(), available }.into());
            }
        }
        let mut survey = Survey {
            file: &file,
            sizes: ArraySizes { joints: run.joints.len(), contacts: run.contacts.len() },
            tree: FrameTree::default(),
            whole: Whole {
                has_contact_states: has_contacts,
                has_events: count(schemas::topics::CONTACT_EVENTS) > 0,
                counts: DRAWN.iter().map(|t| (t.to_string(), count(t))).collect(),
                envelopes: {
                    let (t0, t_end) = times.0.unwrap_or((0.0, 0.0));
                    let e = Envelope::new(t0, t_end);
                    Envelopes {
                        current: e.clone(),
                        voltage: e.clone(),
                        normal_force: e.clone(),
                        slip_speed: e.clone(),
                        friction_ratio: e.clone(),
                        friction_force: e.clone(),
                        contact_mode: e.clone(),
                        electric_energy: e.clone(),
                        link_work: e,
                    }
                },
                ..Whole::default()
            },
            n_tf: count(schemas::topics::TF),
            n_hand: count(schemas::topics::HAND),
            force_topic,
            hand_k: 0,
            motors: None,
            motor_times: times.0,
            joints: run.joints.len(),
            friction: run.contacts.iter().map(|c| c.friction.unwrap_or(0.0)).collect(),
            scene: None,
            error: None,
        };
        let read = schemas::stream_recording(path, Some(&SURVEYED), &mut survey);
        first_error(read, survey.error.take())?;
        let Survey { tree, mut whole, motors, scene, .. } = survey;
        run.scene = scene.unwrap_or_default();
        if let Some((cur, volt)) = motors {
            whole.current_range = cur.finish();
            whole.voltage_range = if whole.has_voltage { volt.finish() } else { None };
        } else {
            whole.voltage_every_joint = false;
        }
        run.root_frame = tree.root(&file)?;
        for c in &mut run.contacts {
            match &c.link {
                Some(link) if !tree.frames.is_empty() && !tree.contains(link) => {
                    return Err(bad(&file, format!("contact {:?}: link {link:?} has no transform in /tf", c.name)));
                }
                Some(_) if tree.frames.is_empty() => c.link = None,
                _ => {}
            }
        }
        run.frames = tree.frames;
        run.whole = whole;
        Ok(run)
    }

    /// What is drawn from `rec`'s metadata: names, contacts, planes, visuals, result (no
    /// samples, no frames).
    pub fn describe(rec: &Recording, stem: &str) -> Result<Run, Error> {
        let file = rec.source.clone();
        let desc = rec.run_opt()?;
        let (name, joints, active) = match desc {
            Some(d) => (d.run, d.joint_names, d.contacts),
            None => (stem.to_string(), Vec::new(), Vec::new()),
        };

        // geometry (a recording of another producer may have no URDF: no visuals then)
        let xml = rec.record_opt::<schemas::UrdfRecord>()?.map(|u| u.xml).unwrap_or_default();
        let links = urdf::links(&xml).map_err(|e| bad(&file, format!("metadata urdf: {e}")))?;
        let visuals = urdf::primitive_visuals(&links);
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
            let shape = info.and_then(|i| i.shape.clone());
            // the record's link and point win (a capsule's ends and the table's contacts from
            // URDF collisions are no entry of the scene's `contacts`)
            let (link, offset_m) = match &shape {
                Some(s) => (Some(s.link.clone()), s.center),
                None => (link, offset_m),
            };
            contacts.push(ContactPoint { name: cname.clone(), link, offset_m, plane, tangents: info.map(|i| (i.t1, i.t2)), friction: info.and_then(|i| i.friction), shape });
        }
        let mut other_planes = Vec::new();
        for c in &scene_contacts {
            if let Some(p) = scene_plane(c) {
                if !contacts.iter().any(|k| k.plane == Some(p)) && !other_planes.contains(&p) {
                    other_planes.push(p);
                }
            }
        }
        Ok(Run {
            name,
            joints,
            contacts,
            other_planes,
            root_frame: "world".to_string(),
            frames: Vec::new(),
            tf_times_ns: Vec::new(),
            visuals,
            links,
            hand: Vec::new(),
            motors: Vec::new(),
            energy: Vec::new(),
            constraints: Vec::new(),
            contact_states: None,
            events: Vec::new(),
            result: rec.result()?,
            scene: schemas::markers::SceneRead::default(),
            whole: Whole::default(),
        })
    }

    /// The samples of a time window dropped (the run as [`Run::survey`] left it).
    pub fn clear_samples(&mut self) {
        for (_, f) in &mut self.frames {
            f.in_parent.clear();
        }
        self.tf_times_ns.clear();
        self.hand.clear();
        self.motors.clear();
        self.energy.clear();
        self.constraints.clear();
        if let Some(c) = &mut self.contact_states {
            c.clear();
        }
        self.events.clear();
    }

    /// The world pose of every frame at sample `k` of the window (the root is the identity).
    pub fn world_poses(&self, k: usize) -> BTreeMap<&str, Pose> {
        world_poses(&self.root_frame, &self.frames, |i| self.frames[i].1.in_parent[k])
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
