//! The one force scale of a scene and the force arrow it draws (issue 27 item 3): the arm's
//! weight drawn a third of a mean link long, rounded down to 1, 2 or 5 × 10^k m/N (the
//! round steps of a chart's axis: Heckbert, "Nice numbers for graph labels", Graphics Gems,
//! 1990), the same in every run of the scene and in both viewers; an arrow from the contact
//! point's projection on its plane, `max(|F| × scale, shortest)` long.

use super::{LEGACY_FORCE_SCALE_M_PER_N, MIN_ARROW_LENGTH_M, STANDARD_GRAVITY_M_PER_S2};
#[cfg(doc)]
use crate::topics;

/// The largest `m × 10^k` (m in 1, 2, 5) not above `x > 0` (`x` itself when it is not a
/// positive finite number).
pub fn round_125_down(x: f64) -> f64 {
    if !(x.is_finite() && x > 0.0) {
        return x;
    }
    let p = 10f64.powf(x.log10().floor());
    let m = [5.0, 2.0, 1.0].into_iter().find(|m| m * p <= x * (1.0 + 1e-12)).unwrap_or(1.0);
    m * p
}

/// The length scale of the contact force arrows: one per scene, the same in every run and in
/// both viewers (Foxglove's `/contact_markers`, `analyze view`'s Rerun arrows), written on
/// [`topics::SCENE`] (entity `legend/force_scale`) and in each arrow entity's metadata.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ForceScale {
    /// Arrow length per newton, m/N.
    pub m_per_n: f64,
    /// The force the scale was chosen from (the arm's weight under standard gravity), N.
    pub reference_force_n: f64,
}

impl ForceScale {
    /// The scale of an arm of `mass_kg` (every link) whose `links` moving links reach
    /// `reach_m`: its weight under standard gravity is drawn a third of a mean link long,
    /// rounded down to 1, 2 or 5 × 10^k m/N (the paper arm: 1.0 kg, ten 0.3 m links: 9.8 N
    /// would be 0.1 m, so 10 mm per newton; its elbow forces, up to 32 N, up to 0.32 m). An arm
    /// without mass or length gets [`LEGACY_FORCE_SCALE_M_PER_N`].
    pub fn for_arm(mass_kg: f64, reach_m: f64, links: usize) -> Self {
        let weight = mass_kg * STANDARD_GRAVITY_M_PER_S2;
        let link = reach_m / links.max(1) as f64;
        let raw = link / 3.0 / weight;
        let m_per_n = if raw.is_finite() && raw > 0.0 { round_125_down(raw) } else { LEGACY_FORCE_SCALE_M_PER_N };
        ForceScale { m_per_n, reference_force_n: weight }
    }

    /// The scale of a recording written before the scale came from the scene.
    pub fn legacy() -> Self {
        ForceScale { m_per_n: LEGACY_FORCE_SCALE_M_PER_N, reference_force_n: 0.0 }
    }

    /// Drawn length of a force of magnitude `force_n` ≥ 0, m: `|F| × scale`, at least
    /// [`MIN_ARROW_LENGTH_M`] for a nonzero force, 0 for none.
    pub fn length_m(&self, force_n: f64) -> f64 {
        if force_n > 0.0 {
            (force_n * self.m_per_n).max(MIN_ARROW_LENGTH_M)
        } else {
            0.0
        }
    }

    /// A round force whose arrow is about 0.1 m long (the scale bar's), N.
    pub fn bar_force_n(&self) -> f64 {
        round_125_down(0.1 / self.m_per_n)
    }

    /// The legend, e.g. "force arrows: 10 N = 0.100 m (10 mm per N); shorter than 0.060 m
    /// drawn 0.060 m, value in the label".
    pub fn legend(&self) -> String {
        let f = self.bar_force_n();
        format!(
            "force arrows: {} N = {:.3} m ({} mm per N); shorter than {:.3} m drawn {:.3} m, value in the label",
            fmt_num(f),
            f * self.m_per_n,
            fmt_num(self.m_per_n * 1e3),
            MIN_ARROW_LENGTH_M,
            MIN_ARROW_LENGTH_M
        )
    }
}

/// A number without trailing zeros (`10`, `0.5`, `2.5e-5`).
pub(super) fn fmt_num(x: f64) -> String {
    if x != 0.0 && (x.abs() < 1e-3 || x.abs() >= 1e6) {
        format!("{x:e}")
    } else {
        let s = format!("{x:.6}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    }
}

/// How a contact force is drawn: an arrow from the contact point's projection on its plane
/// (the point on the table's surface) along the force, [`ForceScale::length_m`] long.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ForceGlyph {
    /// Where the arrow starts: the contact point projected on its plane, world frame, m.
    pub tail: [f64; 3],
    /// Unit direction of the force (+x when there is none), world frame.
    pub direction: [f64; 3],
    /// Drawn length, m (0: no force).
    pub length_m: f64,
    /// `|F|`, N.
    pub magnitude_n: f64,
}

impl ForceGlyph {
    /// The glyph of `force` (N, world frame) at contact `point` (m) on the plane `normal · x =
    /// offset` (unit normal), drawn at `scale`.
    pub fn new(point: [f64; 3], normal: [f64; 3], offset: f64, force: [f64; 3], scale: &ForceScale) -> Self {
        let gap = normal[0] * point[0] + normal[1] * point[1] + normal[2] * point[2] - offset;
        let tail = [0, 1, 2].map(|i| point[i] - gap * normal[i]);
        let magnitude_n = (force[0] * force[0] + force[1] * force[1] + force[2] * force[2]).sqrt();
        let direction = if magnitude_n > 0.0 { force.map(|f| f / magnitude_n) } else { [1.0, 0.0, 0.0] };
        ForceGlyph { tail, direction, length_m: scale.length_m(magnitude_n), magnitude_n }
    }

    /// The arrow's tip, world frame, m.
    pub fn tip(&self) -> [f64; 3] {
        [0, 1, 2].map(|i| self.tail[i] + self.length_m * self.direction[i])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The paper arm (1.0 kg, ten 0.3 m links) gets 10 mm per N; scales are 1-2-5 rounded
    /// down; a massless arm gets the legacy scale; the bar is a round force about 0.1 m long.
    #[test]
    fn the_scale_comes_from_the_arm() {
        let s = ForceScale::for_arm(1.0, 3.0, 10);
        assert_eq!(s.m_per_n, 0.01);
        assert!((s.reference_force_n - 9.80665).abs() < 1e-12);
        assert_eq!(s.bar_force_n(), 10.0);
        assert_eq!(ForceScale::for_arm(0.0, 3.0, 10), ForceScale { m_per_n: LEGACY_FORCE_SCALE_M_PER_N, reference_force_n: 0.0 });
        for (x, want) in [(0.0102, 0.01), (0.0099, 0.005), (0.03, 0.02), (7.0, 5.0), (1.0, 1.0), (2e-4, 2e-4)] {
            assert!((round_125_down(x) - want).abs() < 1e-15 * want.max(1.0), "{x}: {}", round_125_down(x));
        }
        assert!(s.legend().starts_with("force arrows: 10 N = 0.100 m (10 mm per N)"), "{}", s.legend());
    }
}
