//! The examples of a command's `--help` as command lines, so that a test can check each parses
//! exactly as written (every command documents its output and shows an example).

/// Every example line of `cmd`'s and its subcommands' `after_help` that starts with the tool's
/// name, split into arguments (quotes honoured; the line is cut at a shell operator `>`, `|`,
/// `&&` or at a run of two spaces, which starts the comment).
pub fn help_examples(cmd: &clap::Command) -> Vec<Vec<String>> {
    let tool = cmd.get_name().to_string();
    let mut out = Vec::new();
    let mut visit = |c: &clap::Command| {
        let Some(help) = c.get_after_help() else { return };
        for line in help.to_string().lines() {
            let line = line.trim_start();
            if !line.starts_with(&format!("{tool} ")) && line != tool {
                continue;
            }
            let line = line.split("  ").next().unwrap_or(line);
            let mut args = Vec::new();
            for word in split(line) {
                if [">", "|", "&&", ";"].contains(&word.as_str()) {
                    break;
                }
                args.push(expand_variables(&word));
            }
            out.push(args);
        }
    };
    visit(cmd);
    for sub in cmd.get_subcommands() {
        visit(sub);
    }
    out
}

/// `${NAME}` as a shell would expand a numeric job variable (`${SLURM_ARRAY_TASK_ID}` → `0`).
fn expand_variables(word: &str) -> String {
    let mut out = String::new();
    let mut rest = word;
    while let Some(i) = rest.find("${") {
        out.push_str(&rest[..i]);
        match rest[i..].find('}') {
            Some(j) => {
                out.push('0');
                rest = &rest[i + j + 1..];
            }
            None => {
                out.push_str(&rest[i..]);
                rest = "";
            }
        }
    }
    out + rest
}

/// Words of a command line; single and double quotes group and are removed.
fn split(line: &str) -> Vec<String> {
    let (mut words, mut word, mut quote, mut any) = (Vec::new(), String::new(), None, false);
    for ch in line.chars() {
        match (quote, ch) {
            (Some(q), c) if c == q => quote = None,
            (Some(_), c) => word.push(c),
            (None, '\'' | '"') => {
                quote = Some(ch);
                any = true;
            }
            (None, ' ') => {
                if any || !word.is_empty() {
                    words.push(std::mem::take(&mut word));
                }
                any = false;
            }
            (None, c) => word.push(c),
        }
    }
    if any || !word.is_empty() {
        words.push(word);
    }
    words
}

/// The checks every tool's command line passes: clap's own consistency check, and every
/// example of every `--help` parses (`parse` is the tool's `try_parse_from`). Panics naming the
/// first failure (a test helper).
pub fn check_command_line(cmd: clap::Command, parse: impl Fn(&[String]) -> Result<(), clap::Error>) {
    cmd.clone().debug_assert();
    let examples = help_examples(&cmd);
    assert!(examples.len() >= 10, "too few examples: {examples:?}");
    for args in examples {
        if let Err(e) = parse(&args) {
            panic!("{args:?}: {e}");
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_split_like_a_shell_and_stop_at_the_comment() {
        assert_eq!(split("analyze summary 'out/**/*.mcap' -j 8"), ["analyze", "summary", "out/**/*.mcap", "-j", "8"]);
        let cmd = clap::Command::new("t").after_help("Examples:\n  t a b  the comment\n  t c > file\n  other x");
        assert_eq!(help_examples(&cmd), [vec!["t", "a", "b"], vec!["t", "c"]]);
    }
}
