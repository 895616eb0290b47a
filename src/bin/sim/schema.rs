//! `sim schema`: the JSON Schema of the scene (or sweep) files, for editors, or their keys as a
//! Markdown reference page; both generated from the parser's own types (`sim::scene::schema`).

use std::path::PathBuf;

use anyhow::Result;
use cli::{exit, print_out, Verbosity};
use sim::scene::schema::{self, FileKind};

/// Print the JSON Schema of the scene files (or of the sweep files), generated from the types
/// the parser reads them with: give a file `"$schema": "<path to the schema>"` as its first key
/// and an editor completes its keys, shows their descriptions and marks a misspelt one.
#[derive(Debug, Clone, clap::Args)]
#[command(after_help = "\
Output: the JSON Schema (draft 2020-12) on standard output, or in FILE with -o; with
-f markdown, every key (type, default, description) as a Markdown reference page. The
repository's copies: sim/scenes/scene.schema.json, sim/scenes/sweep.schema.json and
docs/src/reference/. `sim export-scene` writes the schema next to the scene it exports.

Examples:
  sim schema                                    the scene files' schema
  sim schema sweep -o sweep.schema.json         the sweep files' schema, into a file
  sim schema -f markdown > scene-fields.md      the scene keys as a reference page
  sim schema scene -o my-arm/scene.schema.json  next to a scene that names it")]
pub struct SchemaArgs {
    /// Which files: scene (`sim run`, `sim check`), sweep (`sim sweep`) or study (`sim optimize`).
    #[arg(value_name = "FILES", value_enum, default_value = "scene")]
    pub kind: Kind,
    /// json: the JSON Schema; markdown: its keys as a reference page.
    #[arg(short = 'f', long = "format", value_enum, default_value = "json")]
    pub format: SchemaFormat,
    /// Write it into FILE (created or replaced atomically) instead of standard output.
    #[arg(short = 'o', long = "out", value_name = "FILE")]
    pub out: Option<PathBuf>,
}

/// Which files the schema is of.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Kind {
    Scene,
    Sweep,
    Study,
}

/// How `sim schema` prints.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum SchemaFormat {
    Json,
    Markdown,
}

pub fn run(a: &SchemaArgs, v: Verbosity) -> Result<u8> {
    let kind = match a.kind {
        Kind::Scene => FileKind::Scene,
        Kind::Sweep => FileKind::Sweep,
        Kind::Study => FileKind::Study,
    };
    let text = match a.format {
        SchemaFormat::Json => schema::schema_text(kind),
        SchemaFormat::Markdown => schema::markdown(kind),
    };
    match &a.out {
        None => print_out(&text)?,
        Some(p) => {
            if let Some(dir) = p.parent().filter(|d| !d.as_os_str().is_empty()) {
                cli::create_dir(dir)?;
            }
            cli::write_file(p, &text)?;
            if !v.quiet {
                eprintln!("wrote {}", p.display());
            }
        }
    }
    Ok(exit::SUCCESS)
}
