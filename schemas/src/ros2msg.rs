//! `ros2msg` schemas: the `.msg` text of a ROS 2 message and the types it depends on.
//!
//! Schema text: the main `.msg` definition, then dependent definitions, each after a line of
//! `=` and a `MSG: pkg/Type` (or `pkg/msg/Type`) line, as rosbag2's MCAP storage plugin and
//! <https://mcap.dev/spec/registry#ros2msg> describe it. Supported: primitives `bool byte char
//! int8..int64 uint8..uint64 float32 float64 string` (bounded `string<=N` too), `T[]`,
//! `T[<=N]` and `T[N]` arrays, nested types by `pkg/Type`, `pkg/msg/Type` or bare `Type` (same
//! package first, then a unique short-name match; `Header` = `std_msgs/Header`), and
//! `builtin_interfaces/Time`/`Duration` even when the text omits them. Comments (`#`), constants
//! (`TYPE NAME=VALUE`) and default values are ignored; `wstring` is rejected, and so is a type
//! that contains itself. The parsed [`MsgSchema`] drives the generic CDR decoder in
//! [`crate::cdr`].

#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Prim {
    Bool,
    Byte,
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    I64,
    U64,
    F32,
    F64,
    Str,
}

impl Prim {
    fn parse(s: &str) -> Option<Prim> {
        Some(match s {
            "bool" => Prim::Bool,
            "byte" | "char" => Prim::Byte,
            "int8" => Prim::I8,
            "uint8" => Prim::U8,
            "int16" => Prim::I16,
            "uint16" => Prim::U16,
            "int32" => Prim::I32,
            "uint32" => Prim::U32,
            "int64" => Prim::I64,
            "uint64" => Prim::U64,
            "float32" => Prim::F32,
            "float64" => Prim::F64,
            "string" => Prim::Str,
            _ if s.starts_with("string<=") => Prim::Str,
            _ => return None,
        })
    }
}

#[derive(Debug, Clone, Copy)]
pub(crate) enum FieldType {
    Prim(Prim),
    Struct(usize),
}

#[derive(Debug, Clone, Copy)]
pub(crate) enum Array {
    Scalar,
    Sequence,
    Fixed(usize),
}

#[derive(Debug)]
pub(crate) struct Field {
    pub(crate) name: String,
    pub(crate) ty: FieldType,
    pub(crate) array: Array,
}

#[derive(Debug)]
pub(crate) struct StructDef {
    pub(crate) name: String,
    pub(crate) fields: Vec<Field>,
}

/// A parsed `ros2msg` schema: the root type and every type it uses.
#[derive(Debug)]
pub(crate) struct MsgSchema {
    /// Index 0 is the root type.
    pub(crate) defs: Vec<StructDef>,
}

/// `pkg/msg/Type` -> `pkg/Type`.
fn normalize(name: &str) -> String {
    let parts: Vec<&str> = name.split('/').collect();
    match parts.as_slice() {
        [pkg, "msg", ty] => format!("{pkg}/{ty}"),
        _ => name.to_string(),
    }
}

fn package(name: &str) -> &str {
    name.split('/').next().unwrap_or("")
}

fn is_ident(s: &str) -> bool {
    !s.is_empty() && s.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
}

/// A field line before type resolution.
struct RawField {
    name: String,
    base: String,
    array: Array,
}

/// Parses one field line; `Ok(None)` for blanks, comments and constants.
fn parse_line(line: &str) -> Result<Option<RawField>, String> {
    let line = line.split('#').next().unwrap_or("").trim();
    if line.is_empty() {
        return Ok(None);
    }
    let (ty, rest) = line
        .split_once(char::is_whitespace)
        .ok_or(format!("no field name in {line:?}"))?;
    let rest = rest.trim();
    if let Some((name, _)) = rest.split_once('=') {
        if is_ident(name.trim()) {
            return Ok(None); // constant
        }
    }
    let name = rest.split_whitespace().next().unwrap_or("");
    if !is_ident(name) {
        return Err(format!("bad field name in {line:?}"));
    }
    let (base, array) = match ty.split_once('[') {
        None => (ty, Array::Scalar),
        Some((base, dims)) => {
            let dims = dims
                .strip_suffix(']')
                .ok_or(format!("bad array type {ty:?}"))?;
            let array = if dims.is_empty() || dims.starts_with("<=") {
                Array::Sequence
            } else {
                Array::Fixed(
                    dims.parse()
                        .map_err(|_| format!("bad array size in {ty:?}"))?,
                )
            };
            (base, array)
        }
    };
    Ok(Some(RawField {
        name: name.to_string(),
        base: base.to_string(),
        array,
    }))
}

const TIME_MSG: &str = "int32 sec\nuint32 nanosec";
const BUILTINS: [(&str, &str); 2] = [
    ("builtin_interfaces/Time", TIME_MSG),
    ("builtin_interfaces/Duration", TIME_MSG),
];

/// Parses the schema text of a channel whose schema name is `root_name`.
pub(crate) fn parse(root_name: &str, text: &str) -> Result<MsgSchema, String> {
    // split into (name, field lines) sections
    let mut sections: Vec<(String, Vec<RawField>)> = vec![(normalize(root_name), Vec::new())];
    for (lineno, line) in text.lines().enumerate() {
        let t = line.trim();
        if t.len() >= 3 && t.chars().all(|c| c == '=') {
            sections.push((String::new(), Vec::new()));
            continue;
        }
        let Some(cur) = sections.last_mut() else {
            continue;
        };
        if let Some(name) = t.strip_prefix("MSG:") {
            cur.0 = normalize(name.trim());
            continue;
        }
        if let Some(f) = parse_line(line).map_err(|e| format!("line {}: {e}", lineno + 1))? {
            cur.1.push(f);
        }
    }
    if sections.iter().skip(1).any(|(n, _)| n.is_empty()) {
        return Err("a section after a `===` line has no `MSG: pkg/Type` line".into());
    }
    for (name, text) in BUILTINS {
        if !sections.iter().any(|(n, _)| n == name) {
            let fields = text
                .lines()
                .filter_map(|l| parse_line(l).ok().flatten())
                .collect();
            sections.push((name.to_string(), fields));
        }
    }

    // resolve type references to section indices
    let names: Vec<String> = sections.iter().map(|(n, _)| n.clone()).collect();
    let resolve = |from: &str, base: &str| -> Option<usize> {
        let base = match base {
            "Header" => "std_msgs/Header".to_string(),
            "time" => "builtin_interfaces/Time".to_string(),
            "duration" => "builtin_interfaces/Duration".to_string(),
            _ => normalize(base),
        };
        if let Some(i) = names.iter().position(|n| *n == base) {
            return Some(i);
        }
        if base.contains('/') {
            return None;
        }
        let local = format!("{}/{base}", package(from));
        if let Some(i) = names.iter().position(|n| *n == local) {
            return Some(i);
        }
        let short: Vec<usize> = (0..names.len())
            .filter(|&i| names[i].rsplit('/').next() == Some(base.as_str()))
            .collect();
        (short.len() == 1).then(|| short[0])
    };
    let mut defs = Vec::with_capacity(sections.len());
    for (name, raw) in &sections {
        let mut fields = Vec::with_capacity(raw.len());
        for f in raw {
            if f.base == "wstring" || f.base.starts_with("wstring<=") {
                return Err(format!("{name}.{}: wstring is not supported", f.name));
            }
            let ty = match Prim::parse(&f.base) {
                Some(p) => FieldType::Prim(p),
                None => FieldType::Struct(
                    resolve(name, &f.base)
                        .ok_or(format!("{name}.{}: unknown type {}", f.name, f.base))?,
                ),
            };
            fields.push(Field {
                name: f.name.clone(),
                ty,
                array: f.array,
            });
        }
        defs.push(StructDef {
            name: name.clone(),
            fields,
        });
    }
    let schema = MsgSchema { defs };
    schema.check_acyclic(0, &mut vec![0u8; schema.defs.len()])?;
    Ok(schema)
}

impl MsgSchema {
    /// Depth-first search from `i`: a type containing itself cannot be decoded.
    fn check_acyclic(&self, i: usize, state: &mut [u8]) -> Result<(), String> {
        match state[i] {
            1 => return Err(format!("type {} contains itself", self.defs[i].name)),
            2 => return Ok(()),
            _ => {}
        }
        state[i] = 1;
        for f in &self.defs[i].fields {
            if let FieldType::Struct(j) = f.ty {
                self.check_acyclic(j, state)?;
            }
        }
        state[i] = 2;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cdr::decode;
    use crate::value::Value;

    const SCHEMA: &str = "\
# comment line
int32 A_CONST=5
string NAME = \"x=y\"
Inner[2] pair   # fixed array of nested
uint8[] blob
float32 f 1.5
Header header
bool[<=3] flags
string<=8 short
====
MSG: pkg/msg/Inner
int16 a
float64 b
====
MSG: std_msgs/Header
builtin_interfaces/Time stamp
string frame_id
";

    fn body(le: bool) -> Vec<u8> {
        // hand-made stream, offsets relative to the body start
        let mut b: Vec<u8> = vec![0, u8::from(le), 0, 0];
        let put = |b: &mut Vec<u8>, align: usize, bytes: &[u8]| {
            while !(b.len() - 4).is_multiple_of(align) {
                b.push(0xee);
            }
            let mut v = bytes.to_vec();
            if !le {
                v.reverse();
            }
            b.extend(v);
        };
        for (a, x) in [(-3i16, 0.5f64), (7, -1.25)] {
            put(&mut b, 2, &a.to_le_bytes());
            put(&mut b, 8, &x.to_le_bytes());
        }
        put(&mut b, 4, &3u32.to_le_bytes());
        b.extend([1, 2, 3]);
        put(&mut b, 4, &1.5f32.to_le_bytes());
        put(&mut b, 4, &(-1i32).to_le_bytes());
        put(&mut b, 4, &9u32.to_le_bytes());
        put(&mut b, 4, &3u32.to_le_bytes());
        b.extend(b"fr\0");
        put(&mut b, 4, &2u32.to_le_bytes());
        b.extend([1, 0]);
        put(&mut b, 4, &3u32.to_le_bytes());
        b.extend(b"ab\0");
        b
    }

    #[test]
    fn decodes_nested_arrays_constants_and_both_endiannesses() {
        let s = parse("pkg/msg/Outer", SCHEMA).unwrap();
        for le in [true, false] {
            let v = decode(&s, &body(le)).unwrap();
            assert_eq!(v.get("pair.0.a"), Some(&Value::I64(-3)), "le={le}");
            assert_eq!(v.get("pair.1.b"), Some(&Value::F64(-1.25)));
            assert_eq!(v.get("blob"), Some(&Value::Bytes(vec![1, 2, 3])));
            assert_eq!(v.get("f"), Some(&Value::F64(1.5)));
            assert_eq!(v.get("header.stamp.sec"), Some(&Value::I64(-1)));
            assert_eq!(v.get("header.stamp.nanosec"), Some(&Value::U64(9)));
            assert_eq!(v.get("header.frame_id").and_then(Value::as_str), Some("fr"));
            assert_eq!(v.get("flags.0"), Some(&Value::Bool(true)));
            assert_eq!(v.get("short").and_then(Value::as_str), Some("ab"));
            assert_eq!(v.get("A_CONST"), None);
            assert_eq!(v.get("NAME"), None);
        }
    }

    #[test]
    fn truncation_at_every_length_is_an_error_naming_the_field() {
        let s = parse("pkg/msg/Outer", SCHEMA).unwrap();
        let full = body(true);
        for n in 0..full.len() {
            let e = decode(&s, &full[..n]).unwrap_err();
            assert!(!e.is_empty());
        }
        let e = decode(&s, &full[..30]).unwrap_err();
        assert!(e.contains("field "), "{e}");
    }

    #[test]
    fn bad_schemas_are_errors() {
        assert!(parse("a/B", "Missing x")
            .unwrap_err()
            .contains("unknown type"));
        assert!(parse("a/B", "a/B self")
            .unwrap_err()
            .contains("contains itself"));
        assert!(parse("a/B", "wstring w").is_err());
        assert!(parse("a/B", "int32[x] v").is_err());
        assert!(parse("a/B", "====\nint32 x").is_err());
    }
}
