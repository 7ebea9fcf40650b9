//! The documentation keeps up with the program: every option the command line offers is
//! in the manual's command-line page, and every relative link in the README, `tools/` and
//! `docs/` leads to a file that exists (and, with an anchor, to a heading it has).

use std::collections::BTreeSet;
use std::fs;
use std::path::{Path, PathBuf};
use std::process::Command;

fn repo() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// The long options `gridtrace ARGS --help` lists, without help and version.
fn options_listed(args: &[&str]) -> BTreeSet<String> {
    let out = Command::new(env!("CARGO_BIN_EXE_gridtrace"))
        .args(args)
        .arg("--help")
        .output()
        .expect("gridtrace runs");
    assert!(out.status.success(), "gridtrace {args:?} --help failed");
    let text = String::from_utf8(out.stdout).expect("help is UTF-8");
    let mut options = BTreeSet::new();
    for line in text.lines() {
        let line = line.trim_start();
        // An option's own line starts with it ("-o, --output <FILE>", "--spp <SPP>").
        let first = line.split(", ").last().unwrap_or("");
        if let Some(rest) = first.strip_prefix("--") {
            let name: String = rest
                .chars()
                .take_while(|c| c.is_ascii_alphanumeric() || *c == '-')
                .collect();
            if line.starts_with('-') && !name.is_empty() {
                options.insert(format!("--{name}"));
            }
        }
    }
    options.remove("--help");
    options.remove("--version");
    options
}

/// True when `text` names `option` as a whole word (`--spp` is not found in `--spp-x`).
fn mentions(text: &str, option: &str) -> bool {
    text.match_indices(option).any(|(i, _)| {
        !text[i + option.len()..].starts_with(|c: char| c.is_ascii_alphanumeric() || c == '-')
    })
}

#[test]
fn every_option_is_in_the_command_line_page() {
    let page = fs::read_to_string(repo().join("docs/manual/command-line.md")).unwrap();
    let mut missing = Vec::new();
    for command in [&[][..], &["merge"], &["denoise"]] {
        let options = options_listed(command);
        assert!(
            options.len() >= 4,
            "too few options found for {command:?}: {options:?}"
        );
        for option in options {
            if !mentions(&page, &option) {
                missing.push(format!("{} {option}", command.join(" ")));
            }
        }
    }
    assert!(
        missing.is_empty(),
        "options missing from docs/manual/command-line.md: {missing:?}"
    );
}

/// Every Markdown file of the documentation.
fn documents() -> Vec<PathBuf> {
    let mut files = vec![repo().join("README.md"), repo().join("tools/README.md")];
    let mut folders = vec![repo().join("docs")];
    while let Some(folder) = folders.pop() {
        for entry in fs::read_dir(&folder).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                folders.push(path);
            } else if path.extension().is_some_and(|e| e == "md") {
                files.push(path);
            }
        }
    }
    files.sort();
    files
}

/// The targets of a Markdown file's links and images: `[text](target)` and `src="target"`,
/// outside code blocks and code spans.
fn link_targets(text: &str) -> Vec<String> {
    let mut targets = Vec::new();
    let mut in_code_block = false;
    for line in text.lines() {
        if line.trim_start().starts_with("```") {
            in_code_block = !in_code_block;
            continue;
        }
        if in_code_block {
            continue;
        }
        // Code spans may hold brackets that are not links.
        let prose: String = line.split('`').step_by(2).collect::<Vec<_>>().join(" ");
        for (i, _) in prose.match_indices("](") {
            let rest = &prose[i + 2..];
            if let Some(end) = rest.find(')') {
                targets.push(rest[..end].to_string());
            }
        }
        for (i, _) in prose.match_indices("src=\"") {
            let rest = &prose[i + 5..];
            if let Some(end) = rest.find('"') {
                targets.push(rest[..end].to_string());
            }
        }
    }
    targets
}

/// GitHub's anchor for a heading: lower case, punctuation dropped, spaces as hyphens.
fn anchor_of(heading: &str) -> String {
    heading
        .trim()
        .to_lowercase()
        .chars()
        .filter(|c| c.is_alphanumeric() || *c == ' ' || *c == '-' || *c == '_')
        .map(|c| if c == ' ' { '-' } else { c })
        .collect()
}

fn anchors(markdown: &str) -> BTreeSet<String> {
    markdown
        .lines()
        .filter(|l| l.starts_with('#'))
        .map(|l| anchor_of(l.trim_start_matches('#')))
        .collect()
}

#[test]
fn every_relative_link_resolves() {
    let mut broken = Vec::new();
    let mut checked = 0;
    for file in documents() {
        let text = fs::read_to_string(&file).unwrap();
        for target in link_targets(&text) {
            if target.contains("://") || target.starts_with("mailto:") {
                continue;
            }
            checked += 1;
            let (path, anchor) = target.split_once('#').unwrap_or((&target, ""));
            let destination = if path.is_empty() {
                file.clone()
            } else {
                file.parent().unwrap().join(path)
            };
            if !destination.exists() {
                broken.push(format!("{}: {target} (no such file)", file.display()));
                continue;
            }
            if !anchor.is_empty() {
                let markdown = fs::read_to_string(&destination).unwrap_or_default();
                if !anchors(&markdown).contains(anchor) {
                    broken.push(format!("{}: {target} (no such heading)", file.display()));
                }
            }
        }
    }
    assert!(
        checked > 50,
        "only {checked} links found: is the parser right?"
    );
    assert!(broken.is_empty(), "broken links:\n{}", broken.join("\n"));
}

#[test]
fn the_link_checker_finds_links_and_anchors() {
    let text =
        "See [a](x.md#one-two) and `[not](a link)`.\n```\n[no](code.md)\n```\n<img src=\"p.png\">";
    assert_eq!(link_targets(text), vec!["x.md#one-two", "p.png"]);
    assert_eq!(anchor_of(" One, two: (three)"), "one-two-three");
    assert!(anchors("# Title\n## Layers, denoising\n").contains("layers-denoising"));
    assert!(mentions("`-o, --output FILE`", "--output"));
    assert!(!mentions("`--spp-range`", "--spp"));
}

/// The project's own text files: the README, docs, sources, tests, tools and benchmarks.
fn project_texts() -> Vec<PathBuf> {
    let mut files = vec![repo().join("README.md"), repo().join("Cargo.toml")];
    let mut folders: Vec<PathBuf> = ["docs", "src", "tests", "tools", "benches", "fuzz", ".ci"]
        .iter()
        .map(|f| repo().join(f))
        .collect();
    let skipped = [
        "node_modules",
        "target",
        "fuzz_crashes",
        "fuzz_hangs",
        "corpus",
    ];
    let kinds = ["rs", "md", "sh", "py", "mjs", "toml", "json", "sbatch"];
    while let Some(folder) = folders.pop() {
        let Ok(entries) = fs::read_dir(&folder) else {
            continue;
        };
        for entry in entries {
            let path = entry.unwrap().path();
            let name = path.file_name().unwrap().to_string_lossy().into_owned();
            if path.is_dir() {
                if !skipped.contains(&name.as_str()) {
                    folders.push(path);
                }
            } else if path
                .extension()
                .is_some_and(|e| kinds.contains(&e.to_string_lossy().as_ref()))
                || name == "run"
            {
                files.push(path);
            }
        }
    }
    files
}

/// The repository describes gridtrace as it is; who did what when belongs in `git log`.
/// So no text names a numbered work period (an ordinal before the word for one) or an
/// issue number.
#[test]
fn no_text_tells_the_projects_history() {
    let ordinals = [
        "first",
        "second",
        "third",
        "fourth",
        "fifth",
        "sixth",
        "seventh",
        "eighth",
        "ninth",
        "tenth",
        "eleventh",
        "twelfth",
        "teenth",
        "twentieth",
        "thirtieth",
        "fortieth",
    ];
    let period = ["sess", "ion"].concat();
    let issue = ["iss", "ue "].concat();
    let mut found = Vec::new();
    for file in project_texts() {
        let Ok(text) = fs::read_to_string(&file) else {
            continue;
        };
        for (number, line) in text.lines().enumerate() {
            let lower = line.to_lowercase();
            let words: Vec<&str> = lower
                .split(|c: char| !c.is_alphanumeric() && c != '-')
                .filter(|w| !w.is_empty())
                .collect();
            let names_a_period = words.windows(2).any(|pair| {
                pair[1].starts_with(&period)
                    && (ordinals.iter().any(|o| pair[0].ends_with(o))
                        || pair[0].ends_with("th")
                            && pair[0].starts_with(|c: char| c.is_ascii_digit()))
            });
            let names_an_issue = lower.match_indices(&issue).any(|(i, _)| {
                lower[i + issue.len()..]
                    .trim_start_matches('#')
                    .starts_with(|c: char| c.is_ascii_digit())
            });
            if names_a_period || names_an_issue {
                found.push(format!(
                    "{}:{}: {}",
                    file.display(),
                    number + 1,
                    line.trim()
                ));
            }
        }
    }
    assert!(
        found.is_empty(),
        "history in the repository's text:\n{}",
        found.join("\n")
    );
}
