//! ROS 2 CDR: encoding of [`RosString`] and [`JointState`], and generic decoding of any
//! `ros2msg`-described message into a [`Value`].
//!
//! Layout (OMG CDR as used by ROS 2 / Fast-CDR, "plain" XCDR1; `../shared/VIEWERS.md` (the workplace notes beside the repository)):
//! a 4-byte encapsulation header `00 01 00 00` (CDR, little-endian), then every field
//! little-endian and aligned to its own size (4 for `u32`/`i32` and string or sequence lengths,
//! 8 for `f64`; at most 8), counted from the byte after the header. A string is a `u32` length
//! that includes the terminating NUL, the bytes, then the NUL. A sequence is a `u32` element
//! count followed by the elements; like Fast-CDR, an empty `f64` sequence gets no padding.
//!
//! The decoder also accepts big-endian CDR (`00 00`); other representations (XCDR2, parameter
//! lists) are rejected with an error. An empty struct occupies one placeholder byte, as ROS 2
//! generates. Lengths are checked against the bytes left before anything is allocated.
//!
//! The schema texts are the `.msg` definitions (`ros2msg` schema encoding), with dependent
//! types appended after lines of `=` and `MSG: pkg/Type` headers, as rosbag2's MCAP plugin
//! writes them.
//!
//! Written by hand, on purpose (evaluated November 2026): serde-based CDR encoders exist
//! (`cdr` 0.2, unmaintained since 2021; `cdr-encoding` 0.11, RustDDS's, +5 crates; `re_cdr`, one
//! release) and would replace the ~100 lines of encoding, but the decoding that `analyze` needs —
//! any message described by a `.msg` schema in a file, dynamically — exists only in a rerun
//! internal crate (`re_ros_msg`, no API promise, pinned to an old version to avoid arrow, fields
//! in alphabetical rather than declaration order) or crates that fail on real messages
//! (`ros2_message`: 8-byte values aligned to 4) or need a ROS installation (`r2r`,
//! `rosidl_runtime_rs`). One hand-written module does both directions with one alignment rule,
//! tested against bytes of Fast-CDR's layout (`tests/round_trip.rs`, `tests/robustness.rs`).

use crate::messages::{JointState, Message, RosString};
use crate::ros2msg::{Array, Field, FieldType, MsgSchema, Prim};
use crate::value::Value;

/// Schema name of [`RosString`].
pub const ROS_STRING_SCHEMA: &str = "std_msgs/msg/String";
/// Schema name of [`JointState`].
pub const JOINT_STATE_SCHEMA: &str = "sensor_msgs/msg/JointState";

/// `.msg` text of `std_msgs/msg/String`.
pub const ROS_STRING_MSG: &str = "string data\n";

/// `.msg` text of `sensor_msgs/msg/JointState` with its dependencies.
pub const JOINT_STATE_MSG: &str = "\
# Joint positions (rad), velocities (rad/s) and efforts (N m) of a set of joints.
std_msgs/Header header

string[] name
float64[] position
float64[] velocity
float64[] effort

================================================================================
MSG: std_msgs/Header
# Standard metadata for higher-level stamped data types.
builtin_interfaces/Time stamp
string frame_id

================================================================================
MSG: builtin_interfaces/Time
# Time since the recording started (here), split into seconds and nanoseconds.
int32 sec
uint32 nanosec
";

/// CDR little-endian encapsulation header.
pub const CDR_LE_HEADER: [u8; 4] = [0x00, 0x01, 0x00, 0x00];

/// Appends CDR fields to a buffer; alignment is relative to the byte after the header.
struct CdrWriter<'a> {
    buf: &'a mut Vec<u8>,
    origin: usize,
}

impl<'a> CdrWriter<'a> {
    /// Writes the encapsulation header and starts the aligned body.
    fn new(buf: &'a mut Vec<u8>) -> Self {
        buf.extend_from_slice(&CDR_LE_HEADER);
        let origin = buf.len();
        Self { buf, origin }
    }

    fn align(&mut self, n: usize) {
        let rel = self.buf.len() - self.origin;
        let pad = (n - rel % n) % n;
        self.buf.resize(self.buf.len() + pad, 0);
    }

    fn u32(&mut self, v: u32) {
        self.align(4);
        self.buf.extend_from_slice(&v.to_le_bytes());
    }

    fn i32(&mut self, v: i32) {
        self.align(4);
        self.buf.extend_from_slice(&v.to_le_bytes());
    }

    fn len(&mut self, n: usize) {
        // ROS 2 lengths are u32; 4 G elements are far beyond any recording we write
        self.u32(u32::try_from(n).unwrap_or(u32::MAX));
    }

    fn string(&mut self, s: &str) {
        self.len(s.len() + 1);
        self.buf.extend_from_slice(s.as_bytes());
        self.buf.push(0);
    }

    fn strings(&mut self, v: &[String]) {
        self.len(v.len());
        for s in v {
            self.string(s);
        }
    }

    fn f64s(&mut self, v: &[f64]) {
        self.len(v.len());
        if !v.is_empty() {
            self.align(8);
        }
        for x in v {
            self.buf.extend_from_slice(&x.to_le_bytes());
        }
    }
}

impl Message for RosString {
    fn schema_name() -> String {
        ROS_STRING_SCHEMA.to_string()
    }
    fn schema_encoding() -> &'static str {
        "ros2msg"
    }
    fn schema_data() -> Vec<u8> {
        ROS_STRING_MSG.as_bytes().to_vec()
    }
    fn message_encoding() -> &'static str {
        "cdr"
    }
    fn encode_into(&self, buf: &mut Vec<u8>) {
        buf.reserve(4 + 4 + self.data.len() + 1);
        CdrWriter::new(buf).string(&self.data);
    }
}

impl Message for JointState {
    fn schema_name() -> String {
        JOINT_STATE_SCHEMA.to_string()
    }
    fn schema_encoding() -> &'static str {
        "ros2msg"
    }
    fn schema_data() -> Vec<u8> {
        JOINT_STATE_MSG.as_bytes().to_vec()
    }
    fn message_encoding() -> &'static str {
        "cdr"
    }
    fn encode_into(&self, buf: &mut Vec<u8>) {
        let sec = i32::try_from(self.stamp_ns / 1_000_000_000).unwrap_or(i32::MAX);
        let nanosec = (self.stamp_ns % 1_000_000_000) as u32;
        let mut w = CdrWriter::new(buf);
        // std_msgs/Header: builtin_interfaces/Time stamp, string frame_id
        w.i32(sec);
        w.u32(nanosec);
        w.string(&self.frame_id);
        w.strings(&self.name);
        w.f64s(&self.position);
        w.f64s(&self.velocity);
        w.f64s(&self.effort);
    }
}

/// A CDR decoding failure: what went wrong, and the field path to it.
struct CdrError {
    path: Vec<String>,
    msg: String,
}

impl CdrError {
    fn within(mut self, seg: String) -> Self {
        self.path.push(seg);
        self
    }
    fn render(self) -> String {
        let path: Vec<String> = self.path.into_iter().rev().collect();
        if path.is_empty() {
            self.msg
        } else {
            format!("field {}: {}", path.join("."), self.msg)
        }
    }
}

fn fail<T>(msg: String) -> Result<T, CdrError> {
    Err(CdrError {
        path: Vec::new(),
        msg,
    })
}

struct CdrReader<'a> {
    data: &'a [u8],
    pos: usize,
    little_endian: bool,
}

impl<'a> CdrReader<'a> {
    const ORIGIN: usize = 4;

    fn take(&mut self, n: usize, align: usize) -> Result<&'a [u8], CdrError> {
        let rel = self.pos - Self::ORIGIN;
        let start = self.pos + (align - rel % align) % align;
        let end = start.checked_add(n).filter(|&e| e <= self.data.len());
        let Some(end) = end else {
            return fail(format!(
                "needs {n} bytes at offset {start}, message has {} bytes",
                self.data.len()
            ));
        };
        self.pos = end;
        Ok(&self.data[start..end])
    }

    fn fixed<const N: usize>(&mut self) -> Result<[u8; N], CdrError> {
        let s = self.take(N, N.min(8))?;
        let mut b = [0u8; N];
        b.copy_from_slice(s);
        if !self.little_endian {
            b.reverse();
        }
        Ok(b)
    }

    fn u32(&mut self) -> Result<u32, CdrError> {
        self.fixed::<4>().map(u32::from_le_bytes)
    }

    /// A sequence length or fixed size, checked against the bytes left (every element of any
    /// type takes at least one byte), so garbage cannot make us allocate or loop for long.
    fn count(&mut self, fixed: Option<usize>) -> Result<usize, CdrError> {
        let n = match fixed {
            Some(n) => n,
            None => self.u32()? as usize,
        };
        let left = self.data.len() - self.pos;
        if n > left {
            return fail(format!("array of {n} elements but only {left} bytes left"));
        }
        Ok(n)
    }

    fn string(&mut self) -> Result<String, CdrError> {
        let n = self.u32()? as usize;
        let mut s = self.take(n, 1)?;
        if let [head @ .., 0] = s {
            s = head;
        }
        Ok(String::from_utf8_lossy(s).into_owned())
    }

    fn prim(&mut self, p: Prim) -> Result<Value, CdrError> {
        Ok(match p {
            Prim::Bool => Value::Bool(self.fixed::<1>()?[0] != 0),
            Prim::Byte | Prim::U8 => Value::U64(u64::from(self.fixed::<1>()?[0])),
            Prim::I8 => Value::I64(i64::from(i8::from_le_bytes(self.fixed()?))),
            Prim::I16 => Value::I64(i64::from(i16::from_le_bytes(self.fixed()?))),
            Prim::U16 => Value::U64(u64::from(u16::from_le_bytes(self.fixed()?))),
            Prim::I32 => Value::I64(i64::from(i32::from_le_bytes(self.fixed()?))),
            Prim::U32 => Value::U64(u64::from(self.u32()?)),
            Prim::I64 => Value::I64(i64::from_le_bytes(self.fixed()?)),
            Prim::U64 => Value::U64(u64::from_le_bytes(self.fixed()?)),
            Prim::F32 => Value::F64(f64::from(f32::from_le_bytes(self.fixed()?))),
            Prim::F64 => Value::F64(f64::from_le_bytes(self.fixed()?)),
            Prim::Str => Value::String(self.string()?),
        })
    }

    fn element(&mut self, schema: &MsgSchema, ty: FieldType) -> Result<Value, CdrError> {
        match ty {
            FieldType::Prim(p) => self.prim(p),
            FieldType::Struct(i) => self.structure(schema, i),
        }
    }

    fn field(&mut self, schema: &MsgSchema, f: &Field) -> Result<Value, CdrError> {
        let fixed = match f.array {
            Array::Scalar => return self.element(schema, f.ty),
            Array::Sequence => None,
            Array::Fixed(n) => Some(n),
        };
        let n = self.count(fixed)?;
        if let FieldType::Prim(Prim::U8 | Prim::Byte) = f.ty {
            return Ok(Value::Bytes(self.take(n, 1)?.to_vec()));
        }
        let mut items = Vec::with_capacity(n);
        for k in 0..n {
            items.push(
                self.element(schema, f.ty)
                    .map_err(|e| e.within(k.to_string()))?,
            );
        }
        Ok(Value::List(items))
    }

    fn structure(&mut self, schema: &MsgSchema, i: usize) -> Result<Value, CdrError> {
        let def = &schema.defs[i];
        if def.fields.is_empty() {
            // ROS 2 gives empty messages one `uint8 structure_needs_at_least_one_member`
            self.take(1, 1)?;
            return Ok(Value::Struct(Vec::new()));
        }
        let mut out = Vec::with_capacity(def.fields.len());
        for f in &def.fields {
            let v = self
                .field(schema, f)
                .map_err(|e| e.within(f.name.clone()))?;
            out.push((f.name.clone(), v));
        }
        Ok(Value::Struct(out))
    }
}

/// Decodes one CDR message of `schema`'s root type.
pub(crate) fn decode(schema: &MsgSchema, data: &[u8]) -> Result<Value, String> {
    let little_endian = match data {
        [0x00, 0x01, _, _, ..] => true,
        [0x00, 0x00, _, _, ..] => false,
        [a, b, _, _, ..] => {
            return Err(format!(
                "unsupported CDR representation {a:02x} {b:02x} (plain CDR 00 00 / 00 01 only)"
            ))
        }
        _ => return Err(format!("{} bytes, shorter than the CDR header", data.len())),
    };
    let mut r = CdrReader {
        data,
        pos: CdrReader::ORIGIN,
        little_endian,
    };
    r.structure(schema, 0).map_err(CdrError::render)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ros2msg::parse;
    use crate::Value;

    #[test]
    fn ros_string_bytes_match_viewers_md_layout() {
        let mut buf = Vec::new();
        RosString { data: "hi".into() }.encode_into(&mut buf);
        assert_eq!(buf, [0, 1, 0, 0, 3, 0, 0, 0, b'h', b'i', 0]);
    }

    #[test]
    fn joint_state_bytes_match_viewers_md_layout() {
        let js = JointState {
            stamp_ns: 2_000_000_005,
            frame_id: "w".into(),
            name: vec!["a".into(), "bc".into()],
            position: vec![1.5],
            velocity: vec![],
            effort: vec![-2.0, 0.25],
        };
        let mut buf = Vec::new();
        js.encode_into(&mut buf);
        let mut want: Vec<u8> = vec![0, 1, 0, 0];
        want.extend(2i32.to_le_bytes()); // body offset 0: sec
        want.extend(5u32.to_le_bytes()); // 4: nanosec
        want.extend([2, 0, 0, 0, b'w', 0]); // 8: frame_id "w" (len 2 incl. NUL), ends at 14
        want.extend([0, 0]); // pad to 16
        want.extend(2u32.to_le_bytes()); // 16: name count
        want.extend([2, 0, 0, 0, b'a', 0]); // 20: "a", ends at 26
        want.extend([0, 0]); // pad to 28
        want.extend([3, 0, 0, 0, b'b', b'c', 0]); // 28: "bc", ends at 35
        want.push(0); // pad to 36
        want.extend(1u32.to_le_bytes()); // 36: position count, ends at 40 (8-aligned)
        want.extend(1.5f64.to_le_bytes()); // 40..48
        want.extend(0u32.to_le_bytes()); // 48: velocity count 0, no padding after
        want.extend(2u32.to_le_bytes()); // 52: effort count, ends at 56 (8-aligned, no pad)
        want.extend((-2.0f64).to_le_bytes()); // 56..64
        want.extend(0.25f64.to_le_bytes()); // 64..72
        assert_eq!(buf, want);

        // a float64 sequence whose count ends 4 bytes past an 8-boundary gets 4 bytes of padding
        let js2 = JointState {
            frame_id: "wxyz".into(),
            name: vec!["a".into()],
            position: vec![1.0],
            ..JointState::default()
        };
        let mut buf2 = Vec::new();
        js2.encode_into(&mut buf2);
        let mut want2: Vec<u8> = vec![0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0]; // header, sec, nanosec
        want2.extend([5, 0, 0, 0, b'w', b'x', b'y', b'z', 0, 0, 0, 0]); // 8: "wxyz" 8..17, pad to 20
        want2.extend([1, 0, 0, 0, 2, 0, 0, 0, b'a', 0, 0, 0]); // 20: 1 name, "a" 24..30, pad to 32
        want2.extend([1, 0, 0, 0, 0, 0, 0, 0]); // 32: position count, pad 36..40
        want2.extend(1.0f64.to_le_bytes()); // 40..48
        want2.extend([0, 0, 0, 0, 0, 0, 0, 0]); // 48: velocity count 0, 52: effort count 0
        assert_eq!(buf2, want2);

        // and the generic decoder gets every field back
        let schema = parse(JOINT_STATE_SCHEMA, JOINT_STATE_MSG).unwrap();
        let v = decode(&schema, &buf).unwrap();
        assert_eq!(v.get("header.stamp.sec"), Some(&Value::I64(2)));
        assert_eq!(v.get("header.stamp.nanosec"), Some(&Value::U64(5)));
        assert_eq!(v.get("header.frame_id").and_then(Value::as_str), Some("w"));
        assert_eq!(v.get("name.1").and_then(Value::as_str), Some("bc"));
        assert_eq!(
            v.get("position").and_then(Value::as_f64_vec),
            Some(vec![1.5])
        );
        assert_eq!(v.get("velocity").and_then(Value::as_f64_vec), Some(vec![]));
        assert_eq!(
            v.get("effort").and_then(Value::as_f64_vec),
            Some(vec![-2.0, 0.25])
        );
    }

    #[test]
    fn huge_sequence_length_is_rejected_without_allocating() {
        let s = parse("a/B", "float64[] v").unwrap();
        let e = decode(&s, &[0, 1, 0, 0, 0xff, 0xff, 0xff, 0xff]).unwrap_err();
        assert!(e.contains("4294967295 elements"), "{e}");
        assert!(decode(&s, &[0, 7, 0, 0])
            .unwrap_err()
            .contains("unsupported CDR"));
    }
}
