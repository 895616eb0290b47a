//! The contact labels, `<name> <|F|> N <mode>` (issue 27 item 2), and where they go so that
//! two close contacts' labels do not overlap: one placement, used by `sim`'s Foxglove text
//! primitives on [`crate::topics::CONTACT_MARKERS`] and by `analyze view`'s Rerun labels, so
//! both viewers show the same.
//!
//! A label is a billboard of fixed screen size (Foxglove `TextPrimitive` with
//! `scale_invariant`, Rerun's point labels), so its extent in the world depends on the camera.
//! The placement works with an *anchor box* measured at the default views' scale: centred on
//! the anchor, [`LABEL_CHAR_WIDTH_M`] per character wide (across the view: any horizontal
//! direction, since both viewers orbit about the world's +z) and [`LABEL_ROW_M`] high (along
//! +z). Two labels clash when their anchors are closer horizontally than the sum of their half
//! widths plus [`LABEL_GAP_M`] *and* closer vertically than [`LABEL_ROW_M`]: seen from any
//! azimuth, labels that do not clash are a row apart or side by side.
//!
//! The placement is greedy, in the contacts' order (a label's place depends only on the labels
//! before it, so it is the same in both viewers): each label starts at its default anchor
//! ([`default_anchor`]: above the arrow's tip, or the marker when there is no force) and, while
//! it clashes with a label already placed, is lifted along +z to one row above that label.
//! Each lift puts it above a label it clashed with and heights only grow, so it stops after at
//! most as many lifts as labels before it; it allocates nothing (the sample loop of `sim`).
//! The rule is that of greedy interval stacking in map labelling (Christensen, Marks & Shieber,
//! "An empirical study of algorithms for point-feature label placement", ACM Transactions on
//! Graphics 14(3), 1995: the greedy baseline), with one candidate direction, up.

use super::{ForceGlyph, MarkerMode};

/// Width of one label character at the default views' scale, m (14 px characters about 7 px
/// wide, at about 1.7 mm per pixel: the paper arm's 3 m reach across a 1440 px wide 3D view).
pub const LABEL_CHAR_WIDTH_M: f64 = 0.012;
/// Height of a label row, m (a 14 px line with its spacing at the same scale).
pub const LABEL_ROW_M: f64 = 0.035;
/// Horizontal gap kept between two labels of one row, m.
pub const LABEL_GAP_M: f64 = 0.01;
/// Clearance below which two labels clash, m (rounding of a lift by a row).
const CLASH_TOLERANCE_M: f64 = 1e-9;
/// Lift of a label above its arrow's tip (or marker) along the plane's normal, m.
pub const LABEL_LIFT_M: f64 = 0.02;

/// Writes the label of a contact's force into `out` (cleared first): `<name> <|F|> N <mode>`,
/// e.g. `elbow4 1.4 N bilateral pulling`. Allocates nothing when `out` has room for
/// [`label_capacity`]`(name)`.
pub fn write_label(out: &mut String, name: &str, magnitude_n: f64, mode: MarkerMode) {
    use std::fmt::Write;
    out.clear();
    out.push_str(name);
    // bounded width: at most 8 characters before the unit
    let _ = if magnitude_n.is_finite() && magnitude_n < 99_999.95 { write!(out, " {magnitude_n:.1} N ") } else { write!(out, " {magnitude_n:.2e} N ") };
    out.push_str(mode.name());
}

/// Room a label of contact `name` needs ([`write_label`]).
pub fn label_capacity(name: &str) -> usize {
    name.len() + 48
}

/// A label's anchor box: where it is drawn (world frame, m) and its half width, m.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LabelBox {
    /// The anchor (the label's centre), world frame, m.
    pub anchor: [f64; 3],
    /// Half the label's width at the default views' scale, m.
    pub half_width_m: f64,
}

impl LabelBox {
    /// The box of a label of `chars` characters at `anchor`.
    pub fn new(anchor: [f64; 3], chars: usize) -> Self {
        LabelBox { anchor, half_width_m: 0.5 * chars as f64 * LABEL_CHAR_WIDTH_M }
    }

    /// How far the two boxes are from clashing, m: the larger of the horizontal clearance
    /// (distance across the view minus both half widths and the gap) and the vertical one
    /// (height difference minus a row); negative when they clash.
    pub fn clearance_m(&self, other: &LabelBox) -> f64 {
        let (a, b) = (self.anchor, other.anchor);
        let across = (a[0] - b[0]).hypot(a[1] - b[1]) - self.half_width_m - other.half_width_m - LABEL_GAP_M;
        let up = (a[2] - b[2]).abs() - LABEL_ROW_M;
        across.max(up)
    }
}

/// Where a contact's label starts before placement: [`LABEL_LIFT_M`] along the plane's unit
/// `normal` from the arrow's tip, or from the contact `point` when there is no force (m).
pub fn default_anchor(glyph: &ForceGlyph, point: [f64; 3], normal: [f64; 3]) -> [f64; 3] {
    let at = if glyph.length_m > 0.0 { glyph.tip() } else { point };
    [0, 1, 2].map(|i| at[i] + LABEL_LIFT_M * normal[i])
}

/// Places `labels` (their default anchors on entry) so that no two clash (module doc): each in
/// turn is lifted along +z to a row above the placed label it clashes with, until it clashes
/// with none. Allocates nothing.
pub fn place_labels(labels: &mut [LabelBox]) {
    for i in 1..labels.len() {
        let (placed, rest) = labels.split_at_mut(i);
        let me = &mut rest[0];
        // at most i lifts: each one puts the label above a placed label, and heights only grow
        for _ in 0..=i {
            // the clash that needs the smallest lift: the lowest placed label it clashes with
            let clash = placed.iter().filter(|p| me.clearance_m(p) < -CLASH_TOLERANCE_M).map(|p| p.anchor[2]).fold(f64::INFINITY, f64::min);
            if !clash.is_finite() {
                break;
            }
            me.anchor[2] = clash + LABEL_ROW_M;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The smallest clearance over all pairs, m.
    fn min_clearance(labels: &[LabelBox]) -> f64 {
        let mut m = f64::INFINITY;
        for i in 0..labels.len() {
            for j in 0..i {
                m = m.min(labels[i].clearance_m(&labels[j]));
            }
        }
        m
    }

    /// Nine labels of 30 characters (`joint5 12.3 N bilateral pushing`, 0.36 m wide) 0.3 m
    /// apart on a line (the whole-table run's contacts) clash pairwise; placed, no two clash (clearance ≥ −1e-9 m, the rounding of a lift), only
    /// heights changed, each by whole rows, the first not at all, and neighbours alternate
    /// between two rows. Labels far apart stay where they were.
    #[test]
    fn close_labels_are_stacked_and_far_ones_stay() {
        let start: Vec<LabelBox> = (0..9).map(|k| LabelBox::new([0.3 * k as f64, 0.1, 0.02], 30)).collect();
        assert!(min_clearance(&start) < -0.03, "{}", min_clearance(&start));
        let mut placed = start.clone();
        place_labels(&mut placed);
        assert!(min_clearance(&placed) >= -1e-9, "{placed:?}");
        for (k, (a, b)) in start.iter().zip(&placed).enumerate() {
            assert_eq!(&a.anchor[..2], &b.anchor[..2]);
            let rows = (b.anchor[2] - a.anchor[2]) / LABEL_ROW_M;
            assert!((rows - (k % 2) as f64).abs() < 1e-9, "label {k}: {rows} rows up");
        }
        let far: Vec<LabelBox> = (0..4).map(|k| LabelBox::new([1.0 * k as f64, 0.0, 0.0], 22)).collect();
        let mut same = far.clone();
        place_labels(&mut same);
        assert_eq!(far, same);
    }

    /// Labels at one anchor (two contacts at the same point) end up a row apart each; a label
    /// that clashes with a lifted one is lifted above it; random clusters never clash after
    /// placement (1000 seeds, 2..12 labels within 0.3 m).
    #[test]
    fn any_cluster_is_placed_without_clashes() {
        let mut same: Vec<LabelBox> = (0..5).map(|_| LabelBox::new([0.5, 0.5, 0.1], 30)).collect();
        place_labels(&mut same);
        for (k, l) in same.iter().enumerate() {
            assert!((l.anchor[2] - (0.1 + k as f64 * LABEL_ROW_M)).abs() < 1e-12);
        }
        // a small linear congruential generator: reproducible, no dependency
        let mut s: u64 = 0x2545_f491_4f6c_dd1d;
        let mut next = || {
            s = s.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..1000 {
            let n = 2 + (next() * 10.0) as usize;
            let mut labels: Vec<LabelBox> = (0..n).map(|_| LabelBox::new([0.3 * next(), 0.3 * next(), 0.05 * next()], 10 + (next() * 25.0) as usize)).collect();
            place_labels(&mut labels);
            assert!(min_clearance(&labels) >= -1e-9, "{labels:?}");
        }
    }
}
