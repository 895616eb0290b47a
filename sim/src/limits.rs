//! The bounds on every input and every run, in one place: each a default that no sane scene
//! reaches, checked before the work it bounds, and reported as a typed error naming the file and
//! the field (or the file and the limit).
//!
//! | what | limit | where checked | override |
//! |---|---|---|---|
//! | scene, sweep and URDF files | regular files of at most [`MAX_INPUT_BYTES`] (4 MiB) | [`read_text`], before reading them whole | none |
//! | URDF element nesting | [`MAX_URDF_DEPTH`] (100) | [`xml_shape`], before the XML parser (which recurses) | none |
//! | URDF joints and links | [`MAX_URDF_JOINTS`] (1000) and one more link | [`xml_shape`] before parsing, `Model::from_urdf` after | none |
//! | samples per run (`duration` × `output_rate` + 1) | 2 to [`MAX_SAMPLES`] (10^8) | scene validation | none |
//! | steps per run | `integrator.max_steps`, default 10^8 ([`crate::integrator::DEFAULT_MAX_STEPS`]) | up front for `rk4` (`duration / step`) and for `h_max`, then in the step loop | the scene's `integrator.max_steps` |
//! | wall-clock time per run | [`DEFAULT_MAX_WALL_TIME`] (10 min) | in the step loop | `sim run/sweep/replay --max-wall-time SECONDS` |
//!
//! Why these numbers: the largest scenes in `sim/scenes` are a few kB, the largest URDF
//! (`hard/chain100.urdf`) 60 kB; a chain of 1000 joints with inertias is 0.3 MB. Parsing a URDF
//! with `urdf-rs` (an XML tree, written out again and read by serde) peaked at ~55 MB per MB
//! of text (measured: 220 MB for 4 MiB, 870 MB for 16 MiB, `sim check`), so 4 MiB bounded it;
//! the streaming reader that replaced it (`dynamics::urdf`, quick-xml events) keeps only the
//! elements it reads, and the bound stays. The
//! mass matrix is dense (nv² doubles) and `rosenbrock`'s Jacobian is (3 nv)², so 1000 joints
//! is 8 MB and 72 MB; 10 000 joints would be 0.8 GB and 7 GB. A URDF is flat (the tree is
//! made of references), five or six elements deep; the XML reader once under `urdf-rs` (RustyXML)
//! built and dropped its tree recursively, so deep nesting overflowed the stack (an abort, not
//! an error); quick-xml does not recurse, and the depth bound stays as a limit on input. 10^8 samples of one run are 10^8 `/joint_states` messages, ~20 GB.
//!
//! The nesting scan follows the grammar of tags in XML 1.0 (W3C, 5th ed., 2008): start-,
//! end- and empty-element tags (§3.1), comments (§2.5), processing instructions (§2.6), CDATA
//! sections (§2.7) and the document type declaration (§2.8). It errs on the deep side: it
//! never reports less nesting than a parser will find.

use std::io::Read;
use std::path::Path;
use std::time::Duration;

/// Largest scene, sweep or URDF file read, bytes (4 MiB).
pub const MAX_INPUT_BYTES: u64 = 4 << 20;

/// Deepest element nesting accepted in a URDF (the root `<robot>` is depth 1).
pub const MAX_URDF_DEPTH: usize = 100;

/// Most joints in a URDF (its links may number one more: a tree).
pub const MAX_URDF_JOINTS: usize = 1000;

/// Most values of a joint-space target held in memory (knots × joints, of a joint CSV or of the
/// general IK's grid): 10^7, i.e. 80 MB for the values and as much for the spline's second
/// derivatives, whatever the input's size.
pub const MAX_TARGET_VALUES: usize = 10_000_000;

/// Most samples of one run (`duration × output_rate + 1`).
pub const MAX_SAMPLES: f64 = 1e8;

/// Wall-clock budget of one run unless the command line says otherwise.
pub const DEFAULT_MAX_WALL_TIME: Duration = Duration::from_secs(600);

/// Why an input file was not read.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ReadError {
    #[error("not a regular file (it is a {kind}); give the path of a file")]
    NotAFile { kind: &'static str },
    #[error("more than the limit of {limit} bytes ({size}); no scene or URDF is that large")]
    TooLarge { limit: u64, size: String },
    #[error("not UTF-8 text ({0})")]
    NotText(std::str::Utf8Error),
    #[error("{0}")]
    Io(#[from] std::io::Error),
}

/// The text of the regular file at `path`, at most `limit` bytes: a device, FIFO, directory or
/// socket is refused before it is opened, and a file larger than `limit` (by its length, or by
/// what reading it gives, for files whose length lies) before it is read whole.
pub fn read_text(path: &Path, limit: u64) -> Result<String, ReadError> {
    let meta = std::fs::metadata(path)?;
    if !meta.is_file() {
        return Err(ReadError::NotAFile { kind: file_kind(&meta.file_type()) });
    }
    if meta.len() > limit {
        return Err(ReadError::TooLarge { limit, size: format!("{} bytes", meta.len()) });
    }
    let mut bytes = Vec::with_capacity(usize::try_from(meta.len()).unwrap_or(0));
    std::fs::File::open(path)?.take(limit.saturating_add(1)).read_to_end(&mut bytes)?;
    if bytes.len() as u64 > limit {
        return Err(ReadError::TooLarge { limit, size: format!("at least {} bytes read", bytes.len()) });
    }
    String::from_utf8(bytes).map_err(|e| ReadError::NotText(e.utf8_error()))
}

fn file_kind(t: &std::fs::FileType) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if t.is_char_device() {
            return "character device";
        }
        if t.is_block_device() {
            return "block device";
        }
        if t.is_fifo() {
            return "FIFO";
        }
        if t.is_socket() {
            return "socket";
        }
    }
    if t.is_dir() {
        "directory"
    } else {
        "special file"
    }
}

/// The deepest element nesting of the XML text `xml` (the root element is depth 1), scanning
/// tags only; stops counting once past `stop` (returns a value > `stop`). Malformed text is
/// scanned as far as it goes: the parser reports it.
pub fn xml_depth(xml: &str, stop: usize) -> usize {
    xml_shape(xml, stop).depth
}

/// What [`xml_shape`] finds without parsing.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct XmlShape {
    /// Deepest element nesting (the root is 1), or the first depth past the scan's `stop`.
    pub depth: usize,
    /// Children of the root element named `joint`, and `link` (a URDF's joints and links).
    pub joints: usize,
    pub links: usize,
}

/// [`xml_depth`], and the number of `joint` and `link` children of the root, in one pass (so
/// that a URDF with too many of them is refused before the parser spends time and memory on
/// it).
pub fn xml_shape(xml: &str, stop: usize) -> XmlShape {
    let b = xml.as_bytes();
    let (mut i, mut depth, mut max) = (0usize, 0usize, 0usize);
    let (mut joints, mut links) = (0usize, 0usize);
    // the index just past the first `pat` at or after `from` (the end of the text if none)
    let skip_past = |from: usize, pat: &[u8]| -> usize {
        b.get(from..).and_then(|rest| rest.windows(pat.len()).position(|w| w == pat)).map_or(b.len(), |p| from + p + pat.len())
    };
    while i < b.len() {
        if b[i] != b'<' {
            i += 1;
            continue;
        }
        let rest = &b[i + 1..];
        if rest.starts_with(b"!--") {
            i = skip_past(i + 4, b"-->");
        } else if rest.starts_with(b"![CDATA[") {
            i = skip_past(i + 9, b"]]>");
        } else if rest.starts_with(b"?") {
            i = skip_past(i + 2, b"?>");
        } else if rest.starts_with(b"!") {
            // <!DOCTYPE …> with an optional [internal subset]: to its closing `>` (§2.8)
            let mut j = i + 2;
            let mut bracket = 0i64;
            while j < b.len() && !(b[j] == b'>' && bracket <= 0) {
                match b[j] {
                    b'[' => bracket += 1,
                    b']' => bracket -= 1,
                    _ => {}
                }
                j += 1;
            }
            i = j + 1;
        } else {
            let closing = rest.starts_with(b"/");
            // to the tag's `>`, outside quoted attribute values (which may hold `>`, §3.1)
            let mut j = i + 1;
            let mut quote = None;
            while j < b.len() {
                match (quote, b[j]) {
                    (None, b'"' | b'\'') => quote = Some(b[j]),
                    (Some(q), c) if c == q => quote = None,
                    (None, b'>') => break,
                    _ => {}
                }
                j += 1;
            }
            let empty = !closing && j > i + 1 && b.get(j - 1) == Some(&b'/') && quote.is_none();
            if !closing && depth == 1 {
                let name_end = rest.iter().position(|c| c.is_ascii_whitespace() || *c == b'/' || *c == b'>').unwrap_or(rest.len());
                match &rest[..name_end] {
                    b"joint" => joints += 1,
                    b"link" => links += 1,
                    _ => {}
                }
            }
            if closing {
                depth = depth.saturating_sub(1);
            } else if !empty {
                depth += 1;
                max = max.max(depth);
                if max > stop {
                    return XmlShape { depth: max, joints, links };
                }
            } else {
                max = max.max(depth + 1);
            }
            i = j + 1;
        }
    }
    XmlShape { depth: max, joints, links }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn xml_depth_counts_elements_not_markup() {
        assert_eq!(xml_depth("", 100), 0);
        assert_eq!(xml_depth("<robot/>", 100), 1);
        assert_eq!(xml_depth("<robot><link name='a'><visual/></link></robot>", 100), 3);
        // comments, CDATA, PIs, a doctype and `>`/`/>` inside attribute values are not tags
        let xml = "<?xml version='1.0'?><!DOCTYPE r [<!ENTITY e 'x'>]><!-- <a><b><c> -->\
                   <r a=\"/>\" b='>'><![CDATA[<x><y>]]><s></s></r>";
        assert_eq!(xml_depth(xml, 100), 2);
        let deep = format!("<robot>{}{}</robot>", "<a>".repeat(500), "</a>".repeat(500));
        assert_eq!(xml_depth(&deep, 1000), 501);
        assert_eq!(xml_depth(&deep, 100), 101, "stops counting past the limit");
        // unterminated input is scanned as far as it goes
        assert_eq!(xml_depth("<a><b x='", 100), 2);
        assert_eq!(xml_depth("<a><!-- never closed <b><c>", 100), 1);
    }

    #[test]
    fn xml_shape_counts_the_roots_joints_and_links() {
        let xml = "<robot><link name='a'/><link name='b'><visual/></link><joint name='j'><parent link='a'/></joint>\
                   <gazebo><joint/><link/></gazebo><!-- <joint/> --><jointx/><linkage/></robot>";
        assert_eq!(xml_shape(xml, 100), XmlShape { depth: 3, joints: 1, links: 2 });
    }

    #[test]
    fn read_text_refuses_devices_directories_and_large_files() {
        let dir = tempfile::tempdir().unwrap();
        let msg = |p: &Path, limit| read_text(p, limit).unwrap_err().to_string();
        assert_eq!(msg(dir.path(), 100), "not a regular file (it is a directory); give the path of a file");
        #[cfg(unix)]
        assert!(msg(Path::new("/dev/zero"), 100).contains("character device"));
        let big = dir.path().join("big.json");
        std::fs::File::create(&big).unwrap().set_len(1 << 40).unwrap(); // sparse: nothing is read
        assert_eq!(msg(&big, MAX_INPUT_BYTES), "more than the limit of 4194304 bytes (1099511627776 bytes); no scene or URDF is that large");
        let small = dir.path().join("small.json");
        std::fs::write(&small, "{}").unwrap();
        assert_eq!(read_text(&small, 2).unwrap(), "{}");
        assert!(msg(&small, 1).contains("limit of 1 bytes"));
        std::fs::write(&small, [0xff, 0xfe]).unwrap();
        assert!(msg(&small, 10).starts_with("not UTF-8 text"));
        assert!(msg(&dir.path().join("missing"), 10).contains("No such file"));
    }
}
