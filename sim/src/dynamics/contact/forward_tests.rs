//! The friction's direction near a zero of the slip (`forward.rs`: `friction_direction`,
//! `slip_direction`); split from `forward.rs` for its size.

use super::{friction_direction, slip_direction, SLIP_DIRECTION_SPEED as VS};

fn unit(a: f64) -> [f64; 2] {
    [a.cos(), a.sin()]
}

fn dist(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

/// Coulomb's direction `v_t/|v_t|` from `SLIP_DIRECTION_SPEED` on (to 1e-15), the stored
/// direction at rest and along it (1-D: exact at every speed), a unit vector everywhere, and
/// continuous across `|v_t| = SLIP_DIRECTION_SPEED` with a bounded slope: on every ray at
/// an angle to `stored` (on its side), the direction moves by at most `2 |Δv| / (0.3 v_s)`
/// between neighbouring speeds 1e-3 v_s apart, and by at most 1e-6 across `v_s ± 1e-12 v_s`.
/// The frozen direction it replaces (`slip_direction`) jumps there by the angle between
/// `stored` and `v_t` (checked: > 0.5 for the rays at more than 30°).
#[test]
fn turns_smoothly_from_the_stored_direction_to_coulombs() {
    for &stored_angle in &[0.0, 0.7, -2.1] {
        let stored = unit(stored_angle);
        assert!(dist(friction_direction([0.0, 0.0], stored), stored) <= 1e-15, "at rest");
        for &speed in &[1e-12, 1e-8, 0.5 * VS, VS, 3.0 * VS, 1.0] {
            let d = friction_direction([speed * stored[0], speed * stored[1]], stored);
            assert!(dist(d, stored) <= 1e-15, "along stored at {speed:e}: {d:?}");
        }
        for k in 0..24 {
            // rays within 89° of stored (past 90°: `past_the_zero_the_friction_opposes_the_slip`)
            let off = -1.55 + 3.1 * f64::from(k) / 23.0;
            let ray = unit(stored_angle + off);
            for &speed in &[VS, 1.5 * VS, 1e-3, 2.0] {
                let d = friction_direction([speed * ray[0], speed * ray[1]], stored);
                assert!(dist(d, ray) <= 1e-15, "Coulomb's direction at {speed:e}, ray {off}: {d:?} vs {ray:?}");
            }
            let mut prev = friction_direction([0.0, 0.0], stored);
            for i in 1..=2000 {
                let speed = VS * f64::from(i) * 1e-3;
                let d = friction_direction([speed * ray[0], speed * ray[1]], stored);
                assert!((d[0].hypot(d[1]) - 1.0).abs() <= 1e-15, "not a unit vector: {d:?}");
                assert!(dist(d, prev) <= 2.0 * 1e-3 / 0.3, "ray {off}: the direction jumps by {} at {speed:e} m/s", dist(d, prev));
                prev = d;
            }
            let (below, above) = (VS * (1.0 - 1e-12), VS * (1.0 + 1e-12));
            let jump = dist(friction_direction([below * ray[0], below * ray[1]], stored), friction_direction([above * ray[0], above * ray[1]], stored));
            assert!(jump <= 1e-6, "ray {off}: a jump of {jump:e} across v_s");
            if off.abs() > 0.53 {
                let frozen = dist(slip_direction([below * ray[0], below * ray[1]], stored), slip_direction([above * ray[0], above * ray[1]], stored));
                assert!(frozen > 0.5, "the frozen direction's jump {frozen} at ray {off}");
            }
        }
    }
}
