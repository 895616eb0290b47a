//! The README and the docs book (`docs/`, mdBook) as a reader meets them:
//! - every link resolves: the file, and the `#anchor` as mdBook makes heading ids (lower case,
//!   spaces to `-`, other punctuation dropped, `-1`, `-2` … for repeats); every page of
//!   `docs/src` is in `SUMMARY.md`;
//! - every command block marked `sh,runnable` runs as written, against the tools this test
//!   built (a page's blocks in order, in one fresh directory per page where `sim/scenes/` and
//!   `recordings/` are the repository's; `cargo run … --bin NAME -- ARGS` runs the built
//!   binary);
//! - the generated reference pages (the CLI of both tools, the recording topics) are what the
//!   code generates today (`ELBOW_BLESS=1` rewrites them);
//! - the code-layout page names every module, and no path on it is missing;
//! - the README stays a front door (≤ 250 lines) with the two set-up commands CI runs;
//! - no file of the repository names a path of the machine it was written on.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn docs_src() -> PathBuf {
    root().join("docs/src")
}

fn read(p: &Path) -> String {
    std::fs::read_to_string(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// Every `.md` file under `dir`, sorted.
fn md_files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap().map(Result::unwrap) {
            let p = e.path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|x| x == "md") {
                out.push(p);
            }
        }
    }
    out.sort();
    out
}

/// The `{{#include PATH[:…]}}` directives of a page: (the directive, the included file).
fn includes(page: &Path, text: &str) -> Vec<(String, PathBuf)> {
    let mut out = Vec::new();
    let mut rest = text;
    while let Some(i) = rest.find("{{#include ") {
        let after = &rest[i..];
        let Some(end) = after.find("}}") else { break };
        let directive = after[..end + 2].to_string();
        let arg = after["{{#include ".len()..end].trim();
        let path = arg.split(':').next().unwrap_or(arg);
        out.push((directive, page.parent().unwrap().join(path)));
        rest = &after[end + 2..];
    }
    out
}

/// The page as mdBook renders it: every include directive replaced by the file it names.
fn expanded(page: &Path) -> String {
    let mut text = read(page);
    let directives = includes(page, &text);
    for (directive, file) in directives {
        assert!(file.is_file(), "{}: {directive} names a missing file", page.display());
        text = text.replace(&directive, &read(&file));
    }
    text
}

/// The text of `md` with fenced code blocks blanked (kept as empty lines, so line numbers
/// hold) and inline code removed: links and headings are only looked for outside code.
fn prose_lines(md: &str) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    let mut fence: Option<&str> = None;
    for (i, line) in md.lines().enumerate() {
        let t = line.trim_start();
        if let Some(f) = fence {
            if t.starts_with(f) {
                fence = None;
            }
            continue;
        }
        if t.starts_with("```") || t.starts_with("~~~") {
            fence = Some(if t.starts_with("```") { "```" } else { "~~~" });
            continue;
        }
        // inline code spans
        let mut s = String::new();
        let mut in_code = false;
        for c in line.chars() {
            if c == '`' {
                in_code = !in_code;
            } else if !in_code {
                s.push(c);
            }
        }
        out.push((i + 1, s));
    }
    out
}

/// mdBook's heading id of `text` (`normalize_id`).
fn heading_id(text: &str) -> String {
    text.chars()
        .filter_map(|c| {
            if c.is_alphanumeric() || c == '_' || c == '-' {
                Some(c.to_lowercase().next().unwrap())
            } else if c.is_whitespace() {
                Some('-')
            } else {
                None
            }
        })
        .collect()
}

/// The anchors a rendered page has: its headings' ids (with mdBook's `-N` for repeats, or an
/// explicit `{#id}`) and `id`/`name` attributes of inline HTML.
fn anchors(md: &str) -> BTreeSet<String> {
    let mut ids = BTreeSet::new();
    let mut seen: BTreeMap<String, usize> = BTreeMap::new();
    let mut fence = false;
    for line in md.lines() {
        let t = line.trim_start();
        if t.starts_with("```") || t.starts_with("~~~") {
            fence = !fence;
            continue;
        }
        if fence {
            continue;
        }
        if let Some(h) = t.strip_prefix('#') {
            let h = h.trim_start_matches('#');
            if !h.starts_with(' ') {
                continue;
            }
            let h = h.trim();
            let id = if let (Some(open), true) = (h.rfind("{#"), h.ends_with('}')) {
                h[open + 2..h.len() - 1].to_string()
            } else {
                // the heading's text as rendered: code marks, emphasis and link targets gone
                let mut text = String::new();
                let mut chars = h.chars().peekable();
                while let Some(c) = chars.next() {
                    match c {
                        '`' | '*' => {}
                        ']' if chars.peek() == Some(&'(') => {
                            for c in chars.by_ref() {
                                if c == ')' {
                                    break;
                                }
                            }
                        }
                        '[' => {}
                        c => text.push(c),
                    }
                }
                heading_id(text.trim())
            };
            let n = seen.entry(id.clone()).or_insert(0);
            ids.insert(if *n == 0 { id.clone() } else { format!("{id}-{n}") });
            *n += 1;
        }
        ids.extend(attr_values(line, &["id", "name"]));
    }
    ids
}

/// The values of the HTML attributes `names` (`name="value"`) on a line, in order.
fn attr_values(line: &str, names: &[&str]) -> Vec<String> {
    let mut out = Vec::new();
    for name in names {
        let attr = format!("{name}=\"");
        let mut rest = line;
        while let Some(i) = rest.find(&attr) {
            let after = &rest[i + attr.len()..];
            let Some(end) = after.find('"') else { break };
            out.push(after[..end].to_string());
            rest = &after[end + 1..];
        }
    }
    out
}

/// The link targets of a page (inline `[..](target)`, images, reference definitions
/// `[x]: target`, HTML `href`/`src`), with their line numbers.
fn links(md: &str) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    for (n, line) in prose_lines(md) {
        let mut rest = line.as_str();
        while let Some(i) = rest.find("](") {
            let after = &rest[i + 2..];
            // up to the matching `)` (targets may hold balanced parentheses)
            let mut depth = 0;
            let mut end = None;
            for (j, c) in after.char_indices() {
                match c {
                    '(' => depth += 1,
                    ')' if depth == 0 => {
                        end = Some(j);
                        break;
                    }
                    ')' => depth -= 1,
                    _ => {}
                }
            }
            let Some(end) = end else { break };
            let target = after[..end].split_whitespace().next().unwrap_or("").trim_matches(['<', '>']).to_string();
            out.push((n, target));
            rest = &after[end..];
        }
        let t = line.trim_start();
        if t.starts_with('[') {
            if let Some(i) = t.find("]: ") {
                if !t[..i].contains('(') {
                    out.push((n, t[i + 3..].split_whitespace().next().unwrap_or("").to_string()));
                }
            }
        }
        out.extend(attr_values(&line, &["href", "src"]).into_iter().map(|v| (n, v)));
    }
    out
}

/// Checks every link of `page` (rendered as `text`, links relative to `base`): returns the
/// broken ones.
fn broken_links(page: &Path, text: &str, base: &Path) -> Vec<String> {
    let mut bad = Vec::new();
    for (line, target) in links(text) {
        if target.is_empty() || target.contains("://") || target.starts_with("mailto:") {
            continue;
        }
        let (file, anchor) = match target.split_once('#') {
            Some((f, a)) => (f, Some(a)),
            None => (target.as_str(), None),
        };
        let path = if file.is_empty() { page.to_path_buf() } else { base.join(file) };
        let where_ = format!("{}:{line}: {target}", page.strip_prefix(root()).unwrap_or(page).display());
        if !path.exists() {
            bad.push(format!("{where_} (no such file)"));
            continue;
        }
        if let Some(anchor) = anchor {
            if path.extension().is_some_and(|x| x == "md") {
                let target_text = if path == page { text.to_string() } else { expanded(&path) };
                if !anchors(&target_text).contains(anchor) {
                    bad.push(format!("{where_} (no such anchor)"));
                }
            }
        }
    }
    bad
}

fn summary_pages() -> Vec<PathBuf> {
    let summary = docs_src().join("SUMMARY.md");
    links(&read(&summary)).into_iter().filter(|(_, t)| !t.is_empty()).map(|(_, t)| docs_src().join(t)).collect()
}

#[test]
fn every_link_of_the_readme_and_the_book_resolves() {
    let mut bad = broken_links(&root().join("README.md"), &read(&root().join("README.md")), root());
    for page in md_files(&docs_src()) {
        let text = expanded(&page);
        bad.extend(broken_links(&page, &text, page.parent().unwrap()));
    }
    assert!(bad.is_empty(), "{} broken links:\n{}", bad.len(), bad.join("\n"));
}

#[test]
fn every_page_is_in_the_summary_and_every_summary_entry_exists() {
    let listed: BTreeSet<PathBuf> = summary_pages().into_iter().collect();
    let missing: Vec<_> = listed.iter().filter(|p| !p.is_file()).collect();
    assert!(missing.is_empty(), "SUMMARY.md lists missing pages: {missing:?}");
    let included: BTreeSet<PathBuf> = md_files(&docs_src())
        .iter()
        .flat_map(|p| includes(p, &read(p)).into_iter().map(|(_, f)| f))
        .filter_map(|f| f.canonicalize().ok())
        .collect();
    let orphans: Vec<_> = md_files(&docs_src())
        .into_iter()
        .filter(|p| !p.ends_with("SUMMARY.md") && !listed.contains(p) && !included.contains(&p.canonicalize().unwrap()))
        .collect();
    assert!(orphans.is_empty(), "pages not in SUMMARY.md (mdBook would not render them): {orphans:?}");
    assert!(listed.len() >= 10, "a book of {} pages", listed.len());
}

/// A stand-in `cargo` for the runnable blocks: `cargo run [--release] [--features F |
/// --all-features] [-q] --bin NAME [-- ARGS]` runs the built NAME; anything else fails, so a
/// block cannot build or install behind the test's back.
const CARGO_STANDIN: &str = r#"#!/usr/bin/env bash
[ "$1" = run ] || { echo "docs runner: only 'cargo run ... --bin NAME -- ...' runs here, not: cargo $*" >&2; exit 97; }
shift
bin=
while [ $# -gt 0 ]; do
  case "$1" in
    --release|-q|--quiet|--all-features) shift ;;
    --features|-F) shift 2 ;;
    --features=*) shift ;;
    --bin) bin="$2"; shift 2 ;;
    --) shift; break ;;
    *) echo "docs runner: unexpected cargo argument $1" >&2; exit 97 ;;
  esac
done
[ -n "$bin" ] || { echo "docs runner: cargo run without --bin" >&2; exit 97; }
exec "$(dirname "$0")/$bin" "$@"
"#;

/// The `sh,runnable` blocks of a page: (first line number, text).
fn runnable_blocks(md: &str) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    let mut current: Option<(usize, String)> = None;
    for (i, line) in md.lines().enumerate() {
        let t = line.trim();
        match &mut current {
            None if t == "```sh,runnable" => current = Some((i + 2, String::new())),
            Some(_) if t == "```" => out.push(current.take().unwrap()),
            Some((_, text)) => {
                text.push_str(line);
                text.push('\n');
            }
            None => {}
        }
    }
    out
}

/// Runs `script` with bash in `dir`, killing it after `limit`: (success, output).
fn run_block(script: &str, dir: &Path, bin: &Path, limit: Duration) -> (bool, String) {
    let path = format!("{}:{}", bin.display(), std::env::var("PATH").unwrap_or_default());
    let mut child = Command::new("bash")
        .args(["-e", "-o", "pipefail", "-c", script])
        .current_dir(dir)
        .env("PATH", path)
        .env("NO_COLOR", "1")
        .stdin(std::process::Stdio::null())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("bash starts");
    // drain both pipes on threads so a chatty block cannot block on a full pipe
    let mut so = child.stdout.take().unwrap();
    let mut se = child.stderr.take().unwrap();
    let t_out = std::thread::spawn(move || {
        let mut s = String::new();
        std::io::Read::read_to_string(&mut so, &mut s).ok();
        s
    });
    let t_err = std::thread::spawn(move || {
        let mut s = String::new();
        std::io::Read::read_to_string(&mut se, &mut s).ok();
        s
    });
    let start = Instant::now();
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break Some(s);
        }
        if start.elapsed() > limit {
            child.kill().ok();
            child.wait().ok();
            break None;
        }
        std::thread::sleep(Duration::from_millis(50));
    };
    let out = format!("{}{}", t_out.join().unwrap(), t_err.join().unwrap());
    match status {
        Some(s) => (s.success(), out),
        None => (false, format!("{out}\n(killed after {} s)", limit.as_secs())),
    }
}

#[test]
fn every_runnable_command_of_the_book_runs_as_written() {
    let bin = tempfile::tempdir().unwrap();
    for (name, exe) in [("sim", env!("CARGO_BIN_EXE_sim")), ("analyze", env!("CARGO_BIN_EXE_analyze"))] {
        std::os::unix::fs::symlink(exe, bin.path().join(name)).unwrap();
    }
    let cargo = bin.path().join("cargo");
    std::fs::write(&cargo, CARGO_STANDIN).unwrap();
    std::fs::set_permissions(&cargo, std::os::unix::fs::PermissionsExt::from_mode(0o755)).unwrap();

    let mut failures = Vec::new();
    let mut ran = 0;
    for page in md_files(&docs_src()) {
        let blocks = runnable_blocks(&read(&page));
        if blocks.is_empty() {
            continue;
        }
        // one directory per page, with the repository's scenes and recordings where a user
        // running from the repository root has them
        let dir = tempfile::tempdir().unwrap();
        std::fs::create_dir(dir.path().join("sim")).unwrap();
        std::os::unix::fs::symlink(root().join("sim/scenes"), dir.path().join("sim/scenes")).unwrap();
        std::os::unix::fs::symlink(root().join("recordings"), dir.path().join("recordings")).unwrap();
        for (line, script) in blocks {
            ran += 1;
            let (ok, out) = run_block(&script, dir.path(), bin.path(), Duration::from_secs(600));
            if !ok {
                let tail: Vec<&str> = out.lines().rev().take(30).collect::<Vec<_>>().into_iter().rev().collect();
                failures.push(format!("{}:{line}:\n{script}--- output (last lines):\n{}\n", page.strip_prefix(root()).unwrap().display(), tail.join("\n")));
                break; // later blocks of the page may need this one's files
            }
        }
    }
    assert!(failures.is_empty(), "{} runnable blocks failed:\n{}", failures.len(), failures.join("\n"));
    assert!(ran >= 10, "only {ran} runnable blocks in the book: the tutorial's commands are not tested");
}

/// (committed page, what the code generates today).
fn generated_pages() -> Vec<(PathBuf, String)> {
    let out = tempfile::tempdir().unwrap();
    let mut pages = Vec::new();
    for tool in ["sim", "analyze"] {
        let args = ["man", "--markdown", "-o", out.path().to_str().unwrap(), "-q"];
        let o = if tool == "sim" { crate::run_sim(&args) } else { crate::run_analyze(&args) };
        assert!(o.status.success(), "{tool} man --markdown: {}", String::from_utf8_lossy(&o.stderr));
        pages.push((docs_src().join(format!("reference/{tool}.md")), read(&out.path().join(format!("{tool}.md")))));
    }
    pages.push((docs_src().join("reference/topics.md"), schemas::reference::topics_markdown()));
    pages
}

#[test]
fn the_generated_reference_pages_are_what_the_code_generates() {
    let bless = std::env::var_os("ELBOW_BLESS").is_some();
    let mut stale = Vec::new();
    for (path, now) in generated_pages() {
        let committed = std::fs::read_to_string(&path).unwrap_or_default();
        if committed != now {
            if bless {
                std::fs::write(&path, &now).unwrap();
            } else {
                stale.push(path.strip_prefix(root()).unwrap().display().to_string());
            }
        }
    }
    assert!(
        stale.is_empty(),
        "generated pages out of date: {stale:?}; re-make them with `ELBOW_BLESS=1 cargo test --all-features --test e2e docs_book` and commit"
    );
}

#[test]
fn the_layout_page_names_every_module_and_only_paths_that_exist() {
    let page = docs_src().join("explanation/layout.md");
    let text = read(&page);
    // every word of the page, for "is this module named"
    let words: BTreeSet<String> = text.split(|c: char| !(c.is_alphanumeric() || c == '_' || c == '-')).map(str::to_string).collect();
    let mut unnamed = Vec::new();
    for dir in ["src", "src/bin/sim", "src/bin/analyze", "sim/src", "analyze/src", "schemas/src"] {
        for e in std::fs::read_dir(root().join(dir)).unwrap().map(Result::unwrap) {
            let p = e.path();
            let stem = p.file_stem().unwrap().to_string_lossy().to_string();
            if p.is_dir() || p.extension().is_some_and(|x| x == "rs") {
                if !words.contains(&stem) {
                    unnamed.push(format!("{dir}/{}", e.file_name().to_string_lossy()));
                }
            }
        }
    }
    assert!(unnamed.is_empty(), "the layout page does not name: {unnamed:?}");
    // every backticked path that starts at a top-level folder exists
    let mut missing = Vec::new();
    for (i, span) in text.split('`').enumerate() {
        if i % 2 == 0 {
            continue; // outside backticks
        }
        let s = span.trim();
        let tops = ["src/", "sim/", "analyze/", "schemas/", "tests/", "bench/", "recordings/", "docs/"];
        if tops.iter().any(|t| s.starts_with(t)) && !s.contains(' ') && !s.contains('*') && !s.contains('<') {
            if !root().join(s).exists() {
                missing.push(s.to_string());
            }
        }
    }
    assert!(missing.is_empty(), "the layout page names paths that do not exist: {missing:?}");
}

#[test]
fn the_readme_is_a_front_door_with_the_commands_ci_runs() {
    let readme = read(&root().join("README.md"));
    let lines = readme.lines().count();
    assert!(lines <= 250, "README.md has {lines} lines (the front door keeps to 250: the rest goes in the book)");
    for cmd in ["cargo run --release --bin sim", "cargo test --workspace --all-features"] {
        assert!(readme.contains(cmd), "README.md lost the set-up command {cmd:?}");
    }
    let ci = read(&root().join(".ci/run"));
    assert!(ci.contains("cargo test --workspace --all-features"), ".ci/run no longer runs the README's test command");
    assert!(!readme.contains("COLD_MAIN_TIME") && !readme.contains("COLD_TEST_TIME") && !readme.contains("<!-- MAIN_OUTPUT -->"), "README.md has a placeholder left");
}

/// Paths of the machine a file was written on: a home, the workplace's folders, a session's
/// notes in the temporary directory. (Spelt in pieces so that this file does not match.)
fn machine_path_patterns() -> Vec<String> {
    ["work", "home", "root", "Users"].iter().map(|d| format!("/{d}/")).collect()
}

#[test]
fn no_file_names_a_path_of_the_machine_it_was_written_on() {
    let o = Command::new("git").args(["ls-files", "-z"]).current_dir(root()).output();
    let files: Vec<PathBuf> = match o {
        Ok(o) if o.status.success() => o.stdout.split(|b| *b == 0).filter(|s| !s.is_empty()).map(|s| root().join(String::from_utf8_lossy(s).as_ref())).collect(),
        _ => {
            crate::skip::skip("docs_book::no_file_names_a_path_of_the_machine_it_was_written_on", "not a git checkout (`git ls-files` failed), nothing to list");
            return;
        }
    };
    let patterns = machine_path_patterns();
    let tmp_notes = format!("/{}/", "tmp");
    let mut found = Vec::new();
    for f in &files {
        let rel = f.strip_prefix(root()).unwrap().to_string_lossy().to_string();
        // published URDFs are kept as their authors wrote them (their licences ask it)
        if rel.starts_with("sim/tests/urdf_corpus/") {
            continue;
        }
        let Ok(bytes) = std::fs::read(f) else { continue };
        if bytes.iter().take(8192).any(|b| *b == 0) {
            continue; // binary
        }
        let text = String::from_utf8_lossy(&bytes);
        for (n, line) in text.lines().enumerate() {
            let notes = line.match_indices(&tmp_notes).any(|(i, _)| {
                let word: String = line[i..].chars().take_while(|c| !c.is_whitespace() && !matches!(c, '`' | ')' | '"' | '\'')).collect();
                word.contains("notes")
            });
            if notes || patterns.iter().any(|p| line.contains(p.as_str())) {
                found.push(format!("{rel}:{}: {}", n + 1, line.trim()));
            }
        }
    }
    assert!(found.is_empty(), "machine paths in the repository:\n{}", found.join("\n"));
}
