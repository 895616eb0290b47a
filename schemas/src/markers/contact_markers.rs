//! [`ContactMarkers`]: the message of [`topics::CONTACT_MARKERS`], built once for a run's
//! contacts and updated in place every sample, allocating nothing per sample.
//!
//! A contact that does not touch is not drawn (issue 24 item 2: a separated candidate costs
//! nothing per sample). Foxglove's `foxglove.SceneUpdate`
//! (<https://docs.foxglove.dev/docs/visualization/message-schemas/scene-update>,
//! `.../scene-entity-deletion`) keeps an entity of lifetime 0 until it is replaced or deleted,
//! and a deletion of type `MATCHING_ID` removes the entities of that id stamped before it; so a
//! contact's two entities (`contact/<name>`, `force/<name>`) are in every message while it
//! touches (sticking, sliding, or bilateral: a bilateral contact is never separated, and the
//! bilateral recordings' bytes do not move), its two deletions in the message of the sample
//! where it separates (and in the first message when it starts separated), and nothing of it
//! in the messages while it stays separated. A viewer that replays the messages in order, or
//! one that shows only the last message before the time it seeks to (Foxglove's backfill), sees
//! at every sample exactly the contacts that touch, each in its mode. The labels are placed
//! apart among the drawn contacts only ([`place_labels`]), as `analyze view` places Rerun's.

use foxglove::messages::{scene_entity_deletion, SceneEntityDeletion};

use super::*;

/// The message of [`topics::CONTACT_MARKERS`], built once for a run's contacts and updated in
/// place every sample. Entities of a message, in this order: per contact that touches,
/// `contact/<name>` (a translucent sphere at the contact point, larger than the link there, and
/// a ring on the table around the point's projection, both coloured by mode) and
/// `force/<name>` (the force arrow from the point on the surface, [`ForceGlyph`], and its
/// label, [`write_label`]), then `hand/actual` and `hand/desired`; deletions: those of the
/// contacts that separate at this sample (module doc).
#[derive(Debug, Clone, PartialEq)]
pub struct ContactMarkers {
    /// What is written at this sample.
    msg: SceneUpdate,
    /// Every entity in the order above (two per contact, then the two hands); one that is in
    /// `msg` leaves an empty one here until the next update moves it back.
    entities: Vec<SceneEntity>,
    /// The indices in `entities` of `msg.entities`, in its order.
    in_msg: Vec<usize>,
    /// Each contact's two deletions (ids `contact/<name>`, `force/<name>`), moved in and out
    /// of `msg.deletions` as the entities are.
    deletions: Vec<SceneEntityDeletion>,
    /// The indices in `deletions` of `msg.deletions`, in its order.
    deletions_in_msg: Vec<usize>,
    /// Whether each contact is drawn (in the last message); `true` before the first, so that a
    /// contact separated at the first sample is deleted in it.
    drawn: Vec<bool>,
    contacts: Vec<MarkerContact>,
    scale: ForceScale,
    /// Each contact's label at its default place, from its last drawn sample.
    defaults: Vec<LabelBox>,
    /// The drawn contacts' labels, placed apart every sample ([`place_labels`]).
    placed: Vec<LabelBox>,
}

impl ContactMarkers {
    /// The message for `contacts` in frame `frame_id`, arrows at `scale`.
    pub fn new(frame_id: &str, contacts: &[MarkerContact], scale: ForceScale) -> Self {
        let mut entities = Vec::with_capacity(2 * contacts.len() + 2);
        let entity = |id: String, metadata: Vec<KeyValuePair>| SceneEntity {
            timestamp: Some(timestamp(0)),
            frame_id: frame_id.into(),
            id,
            metadata,
            ..Default::default()
        };
        let sphere = |r: f64, c: Color| SpherePrimitive {
            pose: Some(pose([0.0; 3], identity())),
            size: Some(Vector3 { x: 2.0 * r, y: 2.0 * r, z: 2.0 * r }),
            color: Some(c),
        };
        // the longest mode name, so that writing any mode later needs no allocation
        let longest = [MarkerMode::Separated, MarkerMode::Sticking, MarkerMode::Sliding, MarkerMode::Pushing, MarkerMode::Pulling]
            .iter()
            .map(|m| m.name().len())
            .max()
            .unwrap_or(0);
        // a ring in the xy plane of its pose (turned onto the contact's plane)
        let ring: Vec<Point3> = (0..CONTACT_RING_POINTS)
            .map(|k| {
                let a = std::f64::consts::TAU * k as f64 / CONTACT_RING_POINTS as f64;
                Point3 { x: CONTACT_RING_RADIUS_M * a.cos(), y: CONTACT_RING_RADIUS_M * a.sin(), z: 0.0 }
            })
            .collect();
        for c in contacts {
            let name = &c.name;
            let mut mode = String::with_capacity(longest);
            mode.push_str(MarkerMode::Separated.name());
            let mut e = entity(
                format!("contact/{name}"),
                vec![
                    kv("what", format!("contact point of {name} (sphere) and its point on the table (ring), coloured by mode")),
                    KeyValuePair { key: "mode".into(), value: mode },
                    kv("sphere_radius_m", CONTACT_MARKER_RADIUS_M.to_string()),
                    kv("ring_radius_m", CONTACT_RING_RADIUS_M.to_string()),
                    kv("units", "m"),
                ],
            );
            e.spheres.push(sphere(CONTACT_MARKER_RADIUS_M, colors::color(colors::SEPARATED, 0.45)));
            e.lines.push(LinePrimitive {
                r#type: line_primitive::Type::LineLoop as i32,
                pose: Some(pose([0.0; 3], quat(rotation_between([0.0, 0.0, 1.0], c.normal)))),
                thickness: RING_LINE_WIDTH_M,
                scale_invariant: false,
                points: ring.clone(),
                color: Some(colors::color(colors::SEPARATED, 1.0)),
                colors: Vec::new(),
                indices: Vec::new(),
            });
            entities.push(e);
            let mut a = entity(
                format!("force/{name}"),
                vec![
                    kv("what", format!("force of the table on the arm at {name} (normal + friction), from the point on the table, length = max(|F| x scale, min_length_m)")),
                    kv("scale_m_per_n", scale.m_per_n.to_string()),
                    kv("min_length_m", MIN_ARROW_LENGTH_M.to_string()),
                    kv("units", "m per N"),
                ],
            );
            a.arrows.push(ArrowPrimitive {
                pose: Some(pose([0.0; 3], identity())),
                shaft_length: 0.0,
                shaft_diameter: ARROW_SHAFT_DIAMETER_M,
                head_length: 0.0,
                head_diameter: ARROW_HEAD_DIAMETER_M,
                color: Some(colors::color(colors::SEPARATED, 1.0)),
            });
            let mut text = String::with_capacity(label_capacity(name));
            write_label(&mut text, name, 0.0, MarkerMode::Separated);
            a.texts.push(TextPrimitive {
                pose: Some(pose([0.0; 3], identity())),
                billboard: true,
                font_size: LABEL_FONT_PX,
                scale_invariant: true,
                color: Some(colors::color(colors::SEPARATED, 1.0)),
                text,
            });
            entities.push(a);
        }
        let mut actual = entity("hand/actual".into(), vec![kv("what", "the hand, actual position"), kv("units", "m")]);
        actual.spheres.push(sphere(HAND_ACTUAL_RADIUS_M, colors::color(colors::HAND_ACTUAL, 0.7)));
        entities.push(actual);
        let mut desired = entity("hand/desired".into(), vec![kv("what", "the hand, desired position (target)"), kv("units", "m")]);
        desired.spheres.push(sphere(HAND_DESIRED_RADIUS_M, colors::color(colors::HAND_DESIRED, 0.35)));
        entities.push(desired);
        let labels = vec![LabelBox::new([0.0; 3], 0); contacts.len()];
        let deletions = contacts
            .iter()
            .flat_map(|c| [format!("contact/{}", c.name), format!("force/{}", c.name)])
            .map(|id| SceneEntityDeletion { timestamp: Some(timestamp(0)), r#type: scene_entity_deletion::Type::MatchingId as i32, id })
            .collect();
        ContactMarkers {
            msg: SceneUpdate { deletions: Vec::with_capacity(2 * contacts.len()), entities: Vec::with_capacity(entities.len()) },
            in_msg: Vec::with_capacity(entities.len()),
            entities,
            deletions,
            deletions_in_msg: Vec::with_capacity(2 * contacts.len()),
            drawn: vec![true; contacts.len()],
            contacts: contacts.to_vec(),
            scale,
            placed: labels.clone(),
            defaults: labels,
        }
    }

    /// The scale of the arrows.
    pub fn scale(&self) -> ForceScale {
        self.scale
    }

    /// The message at `t_ns` for `contacts` (in the order of `new`'s contacts; missing ones
    /// keep their last state) and the hand `actual` and `desired` (world frame, m): the
    /// contacts that touch drawn, those that separate at this sample deleted (module doc).
    pub fn update(&mut self, t_ns: u64, contacts: impl IntoIterator<Item = ContactSample>, actual: [f64; 3], desired: [f64; 3]) -> &SceneUpdate {
        // the last message's entities and deletions back to their places
        for (i, e) in self.in_msg.drain(..).zip(self.msg.entities.drain(..)) {
            self.entities[i] = e;
        }
        for (i, d) in self.deletions_in_msg.drain(..).zip(self.msg.deletions.drain(..)) {
            self.deletions[i] = d;
        }
        let stamp = Some(timestamp(t_ns));
        let n = self.contacts.len();
        let (contact_entities, hand) = self.entities.split_at_mut(2 * n);
        for (k, c) in contacts.into_iter().enumerate().take(n) {
            if c.mode == MarkerMode::Separated {
                if self.drawn[k] {
                    for i in [2 * k, 2 * k + 1] {
                        self.deletions[i].timestamp = stamp;
                        self.deletions_in_msg.push(i);
                        self.msg.deletions.push(std::mem::take(&mut self.deletions[i]));
                    }
                }
                self.drawn[k] = false;
                continue;
            }
            self.drawn[k] = true;
            let info = &self.contacts[k];
            let (marker, arrow) = contact_entities[2 * k..2 * k + 2].split_at_mut(1);
            let (marker, arrow) = (&mut marker[0], &mut arrow[0]);
            let mode = &mut marker.metadata[MODE_KEY].value;
            mode.clear();
            mode.push_str(c.mode.name());
            let glyph = ForceGlyph::new(c.point, info.normal, info.offset, c.force, &self.scale);
            if let Some(s) = marker.spheres.first_mut() {
                s.pose = Some(pose(c.point, identity()));
                s.color = Some(colors::color(c.mode.hex(), 0.45));
            }
            if let Some(l) = marker.lines.first_mut() {
                if let Some(p) = l.pose.as_mut() {
                    p.position = Some(Vector3 { x: glyph.tail[0], y: glyph.tail[1], z: glyph.tail[2] });
                }
                l.color = Some(colors::color(c.mode.hex(), 1.0));
            }
            let color = colors::color(c.mode.hex(), 1.0);
            if let Some(a) = arrow.arrows.first_mut() {
                a.pose = Some(pose(glyph.tail, quat(rotation_between([1.0, 0.0, 0.0], glyph.direction))));
                a.head_length = ARROW_HEAD_SHARE * glyph.length_m;
                a.shaft_length = glyph.length_m - a.head_length;
                a.color = Some(color);
            }
            if let Some(t) = arrow.texts.first_mut() {
                // above the tip (the marker when there is no force); placed below, with the others
                t.color = Some(color);
                write_label(&mut t.text, &info.name, glyph.magnitude_n, c.mode);
                self.defaults[k] = LabelBox::new(default_anchor(&glyph, c.point, info.normal), t.text.chars().count());
            }
        }
        // the drawn contacts' labels apart (`labels`): the same placement as `analyze view`'s
        // Rerun labels
        self.placed.clear();
        self.placed.extend((0..n).filter(|&k| self.drawn[k]).map(|k| self.defaults[k]));
        place_labels(&mut self.placed);
        for (k, label) in (0..n).filter(|&k| self.drawn[k]).zip(&self.placed) {
            for i in [2 * k, 2 * k + 1] {
                contact_entities[i].timestamp = stamp;
            }
            if let Some(t) = contact_entities[2 * k + 1].texts.first_mut() {
                t.pose = Some(pose(label.anchor, identity()));
            }
        }
        for (e, p) in hand.iter_mut().zip([actual, desired]) {
            e.timestamp = stamp;
            if let Some(s) = e.spheres.first_mut() {
                if let Some(ps) = s.pose.as_mut() {
                    ps.position = Some(Vector3 { x: p[0], y: p[1], z: p[2] });
                }
            }
        }
        // this message: the drawn contacts' entities, then the hands
        for i in (0..n).filter(|&k| self.drawn[k]).flat_map(|k| [2 * k, 2 * k + 1]).chain([2 * n, 2 * n + 1]) {
            self.in_msg.push(i);
            self.msg.entities.push(std::mem::take(&mut self.entities[i]));
        }
        &self.msg
    }

    /// The message as last updated.
    pub fn message(&self) -> &SceneUpdate {
        &self.msg
    }

    /// Whether contact `k` (in `new`'s order) is drawn in the message as last updated.
    pub fn drawn(&self, k: usize) -> bool {
        self.drawn.get(k).copied().unwrap_or(false)
    }
}
