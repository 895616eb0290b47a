//! A hand-written walk of the protobuf wire format for this crate's own metric messages
//! ([`KnownKind`]): the hot path of `analyze summary` and of `sim`'s table tap.
//!
//! The wire format is the one of the Protocol Buffers Language Guide (proto3), "Encoding"
//! (<https://protobuf.dev/programming-guides/encoding/>): a message is a sequence of records
//! `key = (field number << 3) | wire type` (a varint), then the value: wire type 0 a varint,
//! 1 eight little-endian bytes (`double`), 2 a varint length and that many bytes (a string, a
//! nested message, a packed repeated scalar), 5 four bytes. A repeated scalar may come packed
//! (one length-delimited record) or unpacked (one record per entry), and its entries append; a
//! singular scalar seen twice keeps the last value; a nested message seen twice is merged;
//! fields the schema does not have are skipped; a field that is absent reads as its default.
//!
//! This walk decodes only what `sim` writes and what is plainly valid. Anything else (a known
//! field with another wire type, a group, a malformed varint or length, a name that is not
//! UTF-8, a packed `double` whose length is not a multiple of 8) makes it give up (`None`), and
//! the caller then decodes the message with `prost` (the reference, [`super::known`]), whose
//! result or error is the answer. The tests compare the two on every message of real
//! recordings and on hand-made edge cases (`schemas/tests/wire.rs`).

use crate::messages::{ConstraintState, ContactState, EnergyState, HandState, MotorState, Vec3};

use super::known::{Known, KnownKind};

/// Reads a varint at the front of `buf` (at most 10 bytes; the 10th at most 1, as prost
/// requires), advancing it.
#[inline]
fn varint(buf: &mut &[u8]) -> Option<u64> {
    let mut value = 0u64;
    for (k, &b) in buf.iter().enumerate().take(10) {
        if k == 9 && b > 1 {
            return None;
        }
        value |= u64::from(b & 0x7f) << (7 * k);
        if b < 0x80 {
            *buf = &buf[k + 1..];
            return Some(value);
        }
    }
    None
}

/// One record's value.
enum Wire<'a> {
    Varint(u64),
    /// The eight bytes as a little-endian `u64` (a word: no byte array on the stack).
    Fixed64(u64),
    Len(&'a [u8]),
}

/// Hands each record of the message `buf` to `f` as `(field number, value)`, in order, with
/// its offset; fixed32 records are skipped (none of our fields has that type). `None` on a
/// group, a reserved wire type, field number 0 or anything truncated, or when `f` gives up.
#[inline]
fn walk<'a>(buf: &'a [u8], mut f: impl FnMut(u32, Wire<'a>, usize) -> Option<()>) -> Option<()> {
    let mut rest = buf;
    while !rest.is_empty() {
        let start = buf.len() - rest.len();
        let key = varint(&mut rest)?;
        let key = u32::try_from(key).ok()?;
        let tag = key >> 3;
        if tag == 0 {
            return None;
        }
        let wire = match key & 7 {
            0 => Wire::Varint(varint(&mut rest)?),
            1 => {
                let (bytes, tail) = rest.split_first_chunk::<8>()?;
                rest = tail;
                Wire::Fixed64(u64::from_le_bytes(*bytes))
            }
            2 => {
                let len = usize::try_from(varint(&mut rest)?).ok()?;
                let (bytes, tail) = (rest.get(..len)?, &rest[len..]);
                rest = tail;
                Wire::Len(bytes)
            }
            5 => {
                rest = rest.get(4..)?;
                continue;
            }
            _ => return None, // groups (3, 4) and the reserved 6, 7: prost decides
        };
        f(tag, wire, start)?;
    }
    Some(())
}

/// A singular `double`: only wire type 1.
#[inline]
fn double(w: Wire<'_>) -> Option<f64> {
    match w {
        Wire::Fixed64(b) => Some(f64::from_bits(b)),
        _ => None,
    }
}

/// A repeated `double`: packed (length a multiple of 8) or one unpacked entry; appended.
#[inline]
fn doubles(w: Wire<'_>, out: &mut Vec<f64>) -> Option<()> {
    match w {
        Wire::Fixed64(b) => out.push(f64::from_bits(b)),
        Wire::Len(bytes) => {
            if bytes.len() % 8 != 0 {
                return None;
            }
            out.extend(bytes.chunks_exact(8).map(|c| f64::from_le_bytes(c.try_into().unwrap_or_default())));
        }
        Wire::Varint(_) => return None,
    }
    Some(())
}

/// A repeated `uint32`: packed varints or one unpacked entry; appended, each truncated to 32
/// bits as protobuf (and prost) read a `uint32`.
#[inline]
fn codes(w: Wire<'_>, out: &mut Vec<u32>) -> Option<()> {
    match w {
        Wire::Varint(v) => out.push(v as u32),
        Wire::Len(mut bytes) => {
            while !bytes.is_empty() {
                out.push(varint(&mut bytes)? as u32);
            }
        }
        Wire::Fixed64(_) => return None,
    }
    Some(())
}

/// A `Vec3` message field, merged into `v` (a message field seen twice is merged).
fn vec3(w: Wire<'_>, v: &mut Vec3) -> Option<()> {
    let Wire::Len(bytes) = w else { return None };
    walk(bytes, |tag, w, _| {
        match tag {
            1 => v.x = double(w)?,
            2 => v.y = double(w)?,
            3 => v.z = double(w)?,
            _ => {}
        }
        Some(())
    })
}

/// Where a message's `name` entries lie: from the first one's key to the last one's end, and
/// whether nothing else lies between them.
#[derive(Default)]
struct NameSpan {
    first: Option<usize>,
    end: usize,
    together: bool,
}

impl NameSpan {
    /// A `name` record at `start` (its key) with the value `w`; `buf_len - rest` is its end,
    /// given as `end`.
    fn entry(&mut self, w: &Wire<'_>, start: usize, end: usize) -> Option<()> {
        let Wire::Len(_) = w else { return None };
        self.together = self.first.is_none() || (self.together && self.end == start);
        self.first.get_or_insert(start);
        self.end = end;
        Some(())
    }
}

/// The end offset of a length-delimited record at `start` whose payload is `bytes` (inside `buf`).
fn end_of(buf: &[u8], bytes: &[u8]) -> usize {
    bytes.as_ptr() as usize - buf.as_ptr() as usize + bytes.len()
}

/// Reads the `name` entries (field `tag`) of `buf` into `names` unless their bytes are `raw`
/// (the entries of the message before, then the same names); `raw` becomes their bytes.
fn names(buf: &[u8], tag: u32, span: &NameSpan, names: &mut Vec<String>, raw: &mut Vec<u8>) -> Option<()> {
    let entries = span.first.map_or(&[][..], |first| &buf[first..span.end]);
    if span.together && !raw.is_empty() && raw.as_slice() == entries {
        return Some(());
    }
    raw.clear();
    let mut k = 0;
    walk(buf, |t, w, _| {
        if t != tag {
            return Some(());
        }
        let Wire::Len(bytes) = w else { return None };
        let text = std::str::from_utf8(bytes).ok()?;
        match names.get_mut(k) {
            Some(n) if n == text => {}
            Some(n) => {
                n.clear();
                n.push_str(text);
            }
            None => names.push(text.to_string()),
        }
        k += 1;
        Some(())
    })?;
    names.truncate(k);
    if span.together && !entries.is_empty() {
        raw.extend_from_slice(entries);
    }
    Some(())
}

/// Decodes `data` as a message of `kind` into `slot` (its arrays and names reused: no
/// allocation once they have their size; `raw` holds the bytes its names were read from).
/// `None`: not decoded here (see the module's docs); `slot` and `raw` are then unspecified and
/// the caller decodes with prost.
pub(crate) fn decode_into(kind: KnownKind, data: &[u8], slot: &mut Option<Known>, raw: &mut Vec<u8>) -> Option<()> {
    let fresh = !matches!(
        (kind, &*slot),
        (KnownKind::Hand, Some(Known::Hand(_)))
            | (KnownKind::Motors, Some(Known::Motors(_)))
            | (KnownKind::Constraints, Some(Known::Constraints(_)))
            | (KnownKind::Energy, Some(Known::Energy(_)))
            | (KnownKind::Contacts, Some(Known::Contacts(_)))
    );
    if fresh {
        raw.clear();
        *slot = Some(match kind {
            KnownKind::Hand => Known::Hand(HandState::default()),
            KnownKind::Motors => Known::Motors(MotorState::default()),
            KnownKind::Constraints => Known::Constraints(ConstraintState::default()),
            KnownKind::Energy => Known::Energy(EnergyState::default()),
            KnownKind::Contacts => Known::Contacts(Box::default()),
        });
    }
    let mut span = NameSpan::default();
    match slot.as_mut()? {
        Known::Hand(h) => {
            *h = HandState::default();
            walk(data, |tag, w, _| {
                match tag {
                    1 => h.time = double(w)?,
                    2 => vec3(w, &mut h.actual)?,
                    3 => vec3(w, &mut h.desired)?,
                    4 => vec3(w, &mut h.error)?,
                    5 => h.error_norm = double(w)?,
                    _ => {}
                }
                Some(())
            })?;
        }
        Known::Motors(m) => {
            m.time = 0.0;
            for v in [&mut m.current, &mut m.voltage, &mut m.back_emf, &mut m.electric_power, &mut m.torque] {
                v.clear();
            }
            walk(data, |tag, w, start| {
                match tag {
                    1 => m.time = double(w)?,
                    2 => doubles(w, &mut m.current)?,
                    3 => doubles(w, &mut m.voltage)?,
                    4 => doubles(w, &mut m.back_emf)?,
                    5 => doubles(w, &mut m.electric_power)?,
                    6 => doubles(w, &mut m.torque)?,
                    7 => span.entry(&w, start, len_end(data, &w))?,
                    _ => {}
                }
                Some(())
            })?;
            names(data, 7, &span, &mut m.name, raw)?;
        }
        Known::Constraints(c) => {
            c.time = 0.0;
            for v in [&mut c.normal_force, &mut c.position, &mut c.velocity] {
                v.clear();
            }
            walk(data, |tag, w, start| {
                match tag {
                    1 => c.time = double(w)?,
                    2 => doubles(w, &mut c.normal_force)?,
                    3 => doubles(w, &mut c.position)?,
                    4 => doubles(w, &mut c.velocity)?,
                    5 => span.entry(&w, start, len_end(data, &w))?,
                    _ => {}
                }
                Some(())
            })?;
            names(data, 5, &span, &mut c.name, raw)?;
        }
        Known::Energy(e) => {
            let name = std::mem::take(&mut e.name);
            let (mut link_work, mut electric_energy) = (std::mem::take(&mut e.link_work), std::mem::take(&mut e.electric_energy));
            link_work.clear();
            electric_energy.clear();
            *e = EnergyState { link_work, electric_energy, name, ..EnergyState::default() };
            walk(data, |tag, w, start| {
                match tag {
                    1 => e.time = double(w)?,
                    2 => doubles(w, &mut e.link_work)?,
                    3 => doubles(w, &mut e.electric_energy)?,
                    4 => e.link_work_total = double(w)?,
                    5 => e.electric_energy_total = double(w)?,
                    6 => e.kinetic = double(w)?,
                    7 => e.potential = double(w)?,
                    8 => e.magnetic = double(w)?,
                    9 => e.resistive_loss = double(w)?,
                    10 => e.friction_loss = double(w)?,
                    11 => e.balance_residual = double(w)?,
                    12 => e.gear_friction_loss = double(w)?,
                    13 => span.entry(&w, start, len_end(data, &w))?,
                    _ => {}
                }
                Some(())
            })?;
            names(data, 13, &span, &mut e.name, raw)?;
        }
        Known::Contacts(c) => {
            c.time = 0.0;
            c.mode.clear();
            for v in contact_arrays(c) {
                v.clear();
            }
            walk(data, |tag, w, start| {
                match tag {
                    1 => c.time = double(w)?,
                    2 => span.entry(&w, start, len_end(data, &w))?,
                    3 => codes(w, &mut c.mode)?,
                    4 => doubles(w, &mut c.gap)?,
                    5 => doubles(w, &mut c.gap_rate)?,
                    6 => doubles(w, &mut c.normal_force)?,
                    7 => doubles(w, &mut c.friction_force_t1)?,
                    8 => doubles(w, &mut c.friction_force_t2)?,
                    9 => doubles(w, &mut c.slip_velocity_t1)?,
                    10 => doubles(w, &mut c.slip_velocity_t2)?,
                    11 => doubles(w, &mut c.impact_loss)?,
                    12 => doubles(w, &mut c.friction_work)?,
                    13 => doubles(w, &mut c.damping_loss)?,
                    _ => {}
                }
                Some(())
            })?;
            names(data, 2, &span, &mut c.name, raw)?;
        }
    }
    Some(())
}

/// The end offset in `buf` of a length-delimited record's payload (0 for another wire type,
/// which [`NameSpan::entry`] refuses).
fn len_end(buf: &[u8], w: &Wire<'_>) -> usize {
    match w {
        Wire::Len(bytes) => end_of(buf, bytes),
        _ => 0,
    }
}

/// The `f64` arrays of a `/contacts` message, in field order.
fn contact_arrays(c: &mut ContactState) -> [&mut Vec<f64>; 10] {
    [
        &mut c.gap,
        &mut c.gap_rate,
        &mut c.normal_force,
        &mut c.friction_force_t1,
        &mut c.friction_force_t2,
        &mut c.slip_velocity_t1,
        &mut c.slip_velocity_t2,
        &mut c.impact_loss,
        &mut c.friction_work,
        &mut c.damping_loss,
    ]
}
