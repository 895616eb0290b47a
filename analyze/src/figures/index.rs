//! The index pages: `index.md` and `index.html`, every figure in order, to read top to bottom.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use super::{markup, Figure, FigureError, RunSeries};

/// Writes `dir/index.md` and `dir/index.html` listing `figures` in order (caption, note, the PNG
/// inline, links to the PNG and SVG), after the runs drawn and the files they came from.
pub fn write_index(
    figures: &[Figure],
    runs: &[RunSeries],
    sources: &[PathBuf],
    dir: &Path,
) -> Result<(), FigureError> {
    let write = |name: &str, text: String| {
        let path = dir.join(name);
        schemas::atomic::write_file(&path, text).map(drop).map_err(|e| FigureError::Write(Box::new(e)))
    };
    write("index.md", markdown(figures, runs, sources))?;
    write("index.html", html(figures, runs, sources))
}

const INTRO: &str = "The figures of the paper (Fig. 1-25) and a few more, drawn from the \
recordings by `analyze figures`. Every run has the same colour in every figure. Fig. 1-3 show \
how well the hand follows the circle, Fig. 4-5 the work and electric energy of all links, \
Fig. 6-25 the same per link (even numbers: the work of link j, odd numbers: its motor's \
electric energy). The only dashed line is the target; a y axis marked (log scale) is \
logarithmic; a run whose line lies under another's says so in the legend.";

fn run_lines(runs: &[RunSeries], sources: &[PathBuf]) -> Vec<String> {
    runs.iter()
        .enumerate()
        .map(|(k, r)| {
            let contacts = if r.contacts.is_empty() {
                "none".to_string()
            } else {
                r.contacts.join(", ")
            };
            let file = sources
                .get(k)
                .map(|p| format!(", from `{}`", p.display()))
                .unwrap_or_default();
            format!("{} (contacts: {contacts}){file}", r.name)
        })
        .collect()
}

/// The caption with real sub/superscripts (inline HTML, which Markdown passes through).
fn heading(f: &Figure) -> String {
    markup::html(&f.caption)
}

fn markdown(figures: &[Figure], runs: &[RunSeries], sources: &[PathBuf]) -> String {
    let mut s = String::from("# Figures\n\n");
    let _ = writeln!(s, "{INTRO}\n\nRuns:\n");
    for line in run_lines(runs, sources) {
        let _ = writeln!(s, "- {line}");
    }
    s.push_str("\nContents:\n\n");
    for f in figures {
        let _ = writeln!(s, "- [{}](#{})", heading(f), f.stem);
    }
    let mut extra_started = false;
    for f in figures {
        if f.number.is_none() && !extra_started {
            extra_started = true;
            s.push_str("\n## Beyond the paper\n");
        }
        let _ = write!(
            s,
            "\n<a id=\"{stem}\"></a>\n\n### {title}\n\n{note}\n\n![{alt}]({stem}.png)\n\n\
             [PNG]({stem}.png) · [SVG]({stem}.svg)\n",
            stem = f.stem,
            title = heading(f),
            alt = markup::plain(&f.caption),
            note = markup::html(&f.note),
        );
    }
    s
}

fn esc(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

fn html(figures: &[Figure], runs: &[RunSeries], sources: &[PathBuf]) -> String {
    let mut s = String::from(
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>Figures</title>\n\
         <style>body{font-family:sans-serif;max-width:1040px;margin:auto;padding:1em;line-height:1.4}\
         img{max-width:100%;border:1px solid #ddd}</style>\n</head>\n<body>\n<h1>Figures</h1>\n",
    );
    let intro = esc(INTRO).replace("`analyze figures`", "<code>analyze figures</code>");
    let _ = writeln!(s, "<p>{intro}</p>\n<p>Runs:</p>\n<ul>");
    for line in run_lines(runs, sources) {
        let _ = writeln!(s, "<li>{}</li>", esc(&line.replace('`', "")));
    }
    s.push_str("</ul>\n<p>Contents:</p>\n<ol>\n");
    for f in figures {
        let _ = writeln!(
            s,
            "<li><a href=\"#{}\">{}</a></li>",
            f.stem,
            markup::html(&esc(&f.caption))
        );
    }
    s.push_str("</ol>\n");
    let mut extra_started = false;
    for f in figures {
        if f.number.is_none() && !extra_started {
            extra_started = true;
            s.push_str("<h2>Beyond the paper</h2>\n");
        }
        let _ = writeln!(
            s,
            "<h3 id=\"{stem}\">{title}</h3>\n<p>{note}</p>\n<p><img src=\"{stem}.png\" alt=\"{alt}\"></p>\n\
             <p><a href=\"{stem}.png\">PNG</a> · <a href=\"{stem}.svg\">SVG</a></p>",
            stem = f.stem,
            title = markup::html(&esc(&f.caption)),
            alt = esc(&markup::plain(&f.caption)),
            note = markup::html(&esc(&f.note)),
        );
    }
    s.push_str("</body>\n</html>\n");
    s
}
