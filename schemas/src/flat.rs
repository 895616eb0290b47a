//! The hand-written protobuf encoding of the flat messages whose size grows with a run's
//! contacts (`/contacts`, `/contact_friction`, `/constraints`: a scalar time and, per contact,
//! a name and scalars), byte for byte what `foxglove::Encode`'s derive writes for them
//! (checked against it in the tests below), in one pass.
//!
//! The derive's `encode` walks the message once for its length (`encoded_len`, to check the
//! buffer), and [`crate::messages`]' generic path once more (to reserve), before it writes
//! each element through the generic field calls; for these messages the length is not needed
//! (a `Vec` grows) and each field is one loop. Issue 24 item 2: the nine candidates of
//! whole-table made these three encodings 3.7x those of two-elbow-unilateral
//! (`valgrind --tool=callgrind`, BENCHMARKS.md "Issue 24, eighth pass").
//!
//! The wire format (<https://protobuf.dev/programming-guides/encoding/>): a field is its tag
//! `(number << 3) | wire type` as a varint, then a double as 8 little-endian bytes (wire type
//! 1), an unsigned integer as a varint (0), a string as its length as a varint and its bytes
//! (2). The derive numbers the fields 1, 2, … in declaration order, writes every scalar (a
//! zero too) and a `Vec` as one tagged field per element (not packed).

use crate::messages::{ConstraintState, ContactFriction, ContactState};

/// Wire types (protobuf encoding guide, "Message Structure").
const VARINT: u32 = 0;
const I64: u32 = 1;
const LEN: u32 = 2;

fn varint(buf: &mut Vec<u8>, mut v: u64) {
    while v >= 0x80 {
        buf.push((v as u8) | 0x80);
        v >>= 7;
    }
    buf.push(v as u8);
}

fn tag(number: u32, wire: u32) -> u64 {
    u64::from((number << 3) | wire)
}

fn double(buf: &mut Vec<u8>, number: u32, v: f64) {
    varint(buf, tag(number, I64));
    buf.extend_from_slice(&v.to_le_bytes());
}

fn doubles(buf: &mut Vec<u8>, number: u32, vs: &[f64]) {
    for &v in vs {
        double(buf, number, v);
    }
}

fn uints(buf: &mut Vec<u8>, number: u32, vs: &[u32]) {
    for &v in vs {
        varint(buf, tag(number, VARINT));
        varint(buf, u64::from(v));
    }
}

fn strings(buf: &mut Vec<u8>, number: u32, vs: &[String]) {
    for s in vs {
        varint(buf, tag(number, LEN));
        varint(buf, s.len() as u64);
        buf.extend_from_slice(s.as_bytes());
    }
}

/// [`ContactState`] appended to `buf`.
pub(crate) fn contact_state(m: &ContactState, buf: &mut Vec<u8>) {
    double(buf, 1, m.time);
    strings(buf, 2, &m.name);
    uints(buf, 3, &m.mode);
    for (number, vs) in [
        (4, &m.gap),
        (5, &m.gap_rate),
        (6, &m.normal_force),
        (7, &m.friction_force_t1),
        (8, &m.friction_force_t2),
        (9, &m.slip_velocity_t1),
        (10, &m.slip_velocity_t2),
        (11, &m.impact_loss),
        (12, &m.friction_work),
        (13, &m.damping_loss),
    ] {
        doubles(buf, number, vs);
    }
}

/// [`ContactFriction`] appended to `buf`.
pub(crate) fn contact_friction(m: &ContactFriction, buf: &mut Vec<u8>) {
    double(buf, 1, m.time);
    strings(buf, 2, &m.name);
    uints(buf, 3, &m.mode);
    doubles(buf, 4, &m.slip_speed);
    doubles(buf, 5, &m.friction_use);
}

/// [`ConstraintState`] appended to `buf`.
pub(crate) fn constraint_state(m: &ConstraintState, buf: &mut Vec<u8>) {
    double(buf, 1, m.time);
    doubles(buf, 2, &m.normal_force);
    doubles(buf, 3, &m.position);
    doubles(buf, 4, &m.velocity);
    strings(buf, 5, &m.name);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::messages::Message;

    /// What the derive writes (the encoding of these messages before this module).
    fn derived<T: foxglove::Encode>(m: &T) -> Vec<u8> {
        let mut buf = Vec::new();
        m.encode(&mut buf).expect("a Vec grows");
        buf
    }

    /// Awkward values: signed zeros, NaN, infinities, subnormals, mode codes of one to five
    /// varint bytes, names of 0, 1, 127, 128 and 300 bytes (one- and two-byte lengths) and
    /// non-ASCII ones.
    fn names(n: usize) -> Vec<String> {
        let lens = [0, 1, 127, 128, 300, 5, 9];
        (0..n).map(|k| if k % 3 == 2 { "élbow·7".repeat(k + 1) } else { "x".repeat(lens[k % lens.len()]) }).collect()
    }

    fn values(n: usize, salt: u64) -> Vec<f64> {
        let specials = [0.0, -0.0, f64::NAN, f64::INFINITY, f64::NEG_INFINITY, f64::MIN_POSITIVE / 4.0, 351.6494935294, -1e-300];
        (0..n).map(|k| if k < specials.len() { specials[(k + salt as usize) % specials.len()] } else { (k as f64 * 0.37 + salt as f64).sin() * 10f64.powi(k as i32 % 20 - 10) }).collect()
    }

    fn modes(n: usize) -> Vec<u32> {
        (0..n).map(|k| [0, 1, 2, 3, 127, 128, 16_384, u32::MAX][k % 8]).collect()
    }

    #[test]
    fn the_flat_encoders_write_the_derives_bytes() {
        for n in [0, 1, 2, 9, 20] {
            for time in [0.0, -0.0, 2.5e-3, 5.0] {
                let v = |s| values(n, s);
                let cs = ContactState {
                    time,
                    name: names(n),
                    mode: modes(n),
                    gap: v(1),
                    gap_rate: v(2),
                    normal_force: v(3),
                    friction_force_t1: v(4),
                    friction_force_t2: v(5),
                    slip_velocity_t1: v(6),
                    slip_velocity_t2: v(7),
                    impact_loss: v(8),
                    friction_work: v(9),
                    damping_loss: v(10),
                };
                let cf = ContactFriction { time, name: names(n), mode: modes(n), slip_speed: v(11), friction_use: v(12) };
                let ct = ConstraintState { time, normal_force: v(13), position: v(14), velocity: v(15), name: names(n) };
                // through the trait the writer calls, appended to what the buffer holds
                let check = |mine: &dyn Fn(&mut Vec<u8>), theirs: Vec<u8>, what: &str| {
                    let mut buf = vec![0xAB];
                    mine(&mut buf);
                    assert_eq!(buf[0], 0xAB, "{what}: appended");
                    assert_eq!(&buf[1..], &theirs[..], "{what}, {n} contacts, t = {time}");
                };
                check(&|b| cs.try_encode_into(b).unwrap(), derived(&cs), "ContactState");
                check(&|b| cs.encode_into(b), derived(&cs), "ContactState (encode_into)");
                check(&|b| cf.try_encode_into(b).unwrap(), derived(&cf), "ContactFriction");
                check(&|b| cf.encode_into(b), derived(&cf), "ContactFriction (encode_into)");
                check(&|b| ct.try_encode_into(b).unwrap(), derived(&ct), "ConstraintState");
                check(&|b| ct.encode_into(b), derived(&ct), "ConstraintState (encode_into)");
            }
        }
    }

    /// Mutation check of the test above: a field numbered one off, or a Vec written packed,
    /// gives other bytes than the derive (the comparison can fail).
    #[test]
    fn a_wrong_field_number_or_packing_is_seen() {
        let cs = ContactState { time: 1.0, gap: vec![1.0, 2.0], ..Default::default() };
        let mut buf = Vec::new();
        double(&mut buf, 1, cs.time);
        doubles(&mut buf, 5, &cs.gap);
        assert_ne!(buf, derived(&cs));
        let mut packed = Vec::new();
        double(&mut packed, 1, cs.time);
        varint(&mut packed, tag(4, LEN));
        varint(&mut packed, 16);
        for g in &cs.gap {
            packed.extend_from_slice(&g.to_le_bytes());
        }
        assert_ne!(packed, derived(&cs));
        let mut right = Vec::new();
        contact_state(&cs, &mut right);
        assert_eq!(right, derived(&cs));
    }
}
