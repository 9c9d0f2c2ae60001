//! The repository explains itself: every path a document names is in it, and no file points to a
//! document that is not.
//!
//! - In every Markdown document of the repository (README.md, BENCHMARKS.md, docs/*.md and the
//!   others; fuzz corpora and build output aside), every inline code span that is a repository
//!   path (`services/protocol/src/voting.rs`, `docs/design.md`, `fuzz/`) and every Markdown link or image to
//!   a local file must name something that exists. Fenced code blocks are not read: they hold
//!   commands and their output.
//! - In every source, script and configuration file (`.rs`, `.py`, `.toml`, `.sh`, `.h`, `.lua`,
//!   and scripts with a `#!` line such as `.ci/run`), every Markdown document it cites must be
//!   in the repository: not a design or interface document kept in a folder beside it.
//!
//! A failure lists every file, line and path that does not exist.
#![allow(clippy::unwrap_used, clippy::expect_used)]
#![allow(clippy::panic, clippy::indexing_slicing)]

use std::collections::BTreeSet;
use std::fs;
use std::path::{Component, Path, PathBuf};

/// Directories never read: version control, build output, and the fuzzers' inputs (data, not
/// documents).
fn skipped(relative: &Path) -> bool {
    let s = relative.to_string_lossy();
    s == "fuzz/corpus"
        || s == "fuzz/artifacts"
        || relative.file_name().is_some_and(|n| {
            n == ".git" || n == "target" || n == "__pycache__" || n == "node_modules"
        })
}

/// Every file under `root`, as paths relative to it, but the skipped directories.
fn files(root: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![PathBuf::new()];
    while let Some(dir) = stack.pop() {
        for entry in fs::read_dir(root.join(&dir)).unwrap() {
            let entry = entry.unwrap();
            let relative = dir.join(entry.file_name());
            let kind = entry.file_type().unwrap();
            if kind.is_dir() {
                if !skipped(&relative) {
                    stack.push(relative);
                }
            } else if kind.is_file() {
                out.push(relative);
            }
        }
    }
    out.sort();
    out
}

/// The names at the top of the repository (but build output): a code span whose first component
/// is one of them is a repository path.
fn top_level(root: &Path) -> BTreeSet<String> {
    fs::read_dir(root)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n != "target" && n != ".git")
        .collect()
}

/// `base` joined with `relative`, `..` resolved, if it stays inside the repository.
fn resolve(base: &Path, relative: &str) -> Option<PathBuf> {
    let mut out = PathBuf::new();
    for c in base.join(relative).components() {
        match c {
            Component::ParentDir => {
                if !out.pop() {
                    return None;
                }
            }
            Component::CurDir => {}
            Component::Normal(n) => out.push(n),
            Component::RootDir | Component::Prefix(_) => return None,
        }
    }
    Some(out)
}

/// Whether `relative` (to the repository) exists, for some base among `bases`.
fn exists(root: &Path, bases: &[PathBuf], relative: &str) -> bool {
    bases
        .iter()
        .filter_map(|b| resolve(b, relative))
        .any(|p| root.join(p).exists())
}

/// The text of a Markdown document without its fenced code blocks (their lines left empty, so
/// line numbers stay).
fn without_fences(text: &str) -> String {
    let mut fenced = false;
    text.lines()
        .map(|line| {
            let fence = line.trim_start().starts_with("```");
            if fence {
                fenced = !fenced;
            }
            if fence || fenced { "" } else { line }
        })
        .collect::<Vec<_>>()
        .join("\n")
}

fn line_of(text: &str, offset: usize) -> usize {
    text[..offset].matches('\n').count() + 1
}

/// The inline code spans of a Markdown text (fences removed), with their line. A span may run
/// over a line break.
fn code_spans(text: &str) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    let mut rest = 0;
    while let Some(open) = text[rest..].find('`') {
        let start = rest + open + 1;
        let Some(len) = text[start..].find('`') else {
            break;
        };
        out.push((line_of(text, start), text[start..start + len].to_string()));
        rest = start + len + 1;
    }
    out
}

/// The targets of the Markdown links and images of a text (fences removed), with their line.
fn link_targets(text: &str) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    let mut rest = 0;
    while let Some(at) = text[rest..].find("](") {
        let start = rest + at + 2;
        let end = text[start..]
            .find(|c: char| c == ')' || c.is_whitespace())
            .map_or(text.len(), |e| start + e);
        out.push((line_of(text, start), text[start..end].to_string()));
        rest = end;
    }
    out
}

/// What a code span names in the repository, if it is a repository path: the path, with a
/// trailing placeholder part (`missions/<CHECKSUM>.toml`) cut off.
fn repository_path(span: &str, top: &BTreeSet<String>) -> Option<String> {
    let span = span.trim();
    if span.is_empty()
        || span.contains(char::is_whitespace)
        || span.contains("::")
        || span.starts_with(['/', '~', '$', '-', '<', '[', '#', '*'])
        || span.contains("://")
    {
        return None;
    }
    let span = span.split('#').next().unwrap_or(span);
    if span.starts_with("../") {
        return Some(span.to_string());
    }
    let Some((first, _)) = span.split_once('/') else {
        // A bare file name is a path only when it is a document.
        return span.ends_with(".md").then(|| span.to_string());
    };
    if !top.contains(first) {
        return None;
    }
    let literal: Vec<&str> = span
        .split('/')
        .take_while(|c| !c.contains(['<', '>', '*', '{', '…']) && !c.contains("..."))
        .collect();
    Some(literal.join("/"))
}

/// The `*.md` paths a source file cites, with their line.
fn cited_documents(text: &str) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let bytes = line.as_bytes();
        let mut at = 0;
        while let Some(found) = line[at..].find(".md") {
            let end = at + found + 3;
            let after_ok = bytes
                .get(end)
                .is_none_or(|b| !(b.is_ascii_alphanumeric() || *b == b'_'));
            let start = line[..end - 3]
                .rfind(|c: char| !(c.is_ascii_alphanumeric() || "_./-".contains(c)))
                .map_or(0, |s| s + 1);
            let token = &line[start..end];
            let preceded_by_scheme = line[..start].ends_with(':');
            if after_ok && token.len() > 3 && !token.starts_with('/') && !preceded_by_scheme {
                out.push((n + 1, token.to_string()));
            }
            at = end;
        }
    }
    out
}

fn is_source(root: &Path, relative: &Path) -> bool {
    let ext = relative.extension().and_then(|e| e.to_str()).unwrap_or("");
    if ["rs", "py", "toml", "sh", "h", "lua"].contains(&ext) {
        return true;
    }
    ext.is_empty() && fs::read(root.join(relative)).is_ok_and(|bytes| bytes.starts_with(b"#!"))
}

/// The directories a path written in `file` may be relative to: the repository root, the file's
/// own directory and every directory above it (the README of a crate's `tests/data/`).
fn bases_of(file: &Path) -> Vec<PathBuf> {
    let mut bases = vec![PathBuf::new()];
    let mut dir = file.parent();
    while let Some(d) = dir {
        if !d.as_os_str().is_empty() {
            bases.push(d.to_path_buf());
        }
        dir = d.parent();
    }
    bases
}

/// Every dangling reference of the repository at `root`, one line each, and how many
/// references were checked.
fn dangling(root: &Path) -> (Vec<String>, usize) {
    let top = top_level(root);
    let mut missing = Vec::new();
    let mut checked = 0;
    for file in files(root) {
        let shown = file.display();
        let is_markdown = file.extension().is_some_and(|e| e == "md");
        if !is_markdown && !is_source(root, &file) {
            continue;
        }
        let Ok(text) = fs::read_to_string(root.join(&file)) else {
            continue;
        };
        let dir = file.parent().map(Path::to_path_buf).unwrap_or_default();
        if is_markdown {
            let text = without_fences(&text);
            for (line, span) in code_spans(&text) {
                let Some(path) = repository_path(&span, &top) else {
                    continue;
                };
                checked += 1;
                if !exists(root, &[PathBuf::new(), dir.clone()], &path) {
                    missing.push(format!("{shown}:{line}: `{span}` is not in the repository"));
                }
            }
            for (line, target) in link_targets(&text) {
                if target.contains("://") || target.starts_with(['#', '<']) || target.is_empty() {
                    continue;
                }
                let path = target.split('#').next().unwrap_or(&target);
                checked += 1;
                if !exists(root, std::slice::from_ref(&dir), path) {
                    missing.push(format!(
                        "{shown}:{line}: link ({target}) leads to nothing in the repository"
                    ));
                }
            }
        } else {
            for (line, document) in cited_documents(&text) {
                checked += 1;
                if !exists(root, &bases_of(&file), &document) {
                    missing.push(format!(
                        "{shown}:{line}: cites {document}, which is not in the repository"
                    ));
                }
            }
        }
    }
    (missing, checked)
}

#[test]
fn every_path_a_document_names_is_in_the_repository() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    for document in ["README.md", "BENCHMARKS.md", "docs/design.md"] {
        assert!(root.join(document).is_file(), "{document} is missing");
    }
    let (missing, checked) = dangling(root);
    println!("{checked} references checked");
    // The documents name hundreds of paths: a scan that finds few has stopped reading them.
    assert!(checked > 200, "only {checked} references found");
    assert!(
        missing.is_empty(),
        "{} references lead to nothing:\n{}",
        missing.len(),
        missing.join("\n")
    );
}

/// The scan itself, on a repository made for it: what exists passes, what does not is named
/// with its file and line, and what is no repository path is left alone.
#[test]
fn the_scan_finds_what_is_missing_and_only_that() {
    let root = std::env::temp_dir().join(format!("missionlink-documents-{}", std::process::id()));
    let _ = fs::remove_dir_all(&root);
    fs::create_dir_all(root.join("docs")).unwrap();
    fs::create_dir_all(root.join("services/src")).unwrap();
    fs::create_dir_all(root.join("services/tests/data")).unwrap();
    // The fixtures write `%md` for the documents' extension, so that this file cites none.
    let md = |text: &str| text.replace("%md", ".md");
    let write = |path: &str, text: &str| fs::write(root.join(md(path)), md(text));
    write(
        "services/src/voting.rs",
        "//! See DESIGN%md and docs/a%md.\n",
    )
    .unwrap();
    write(
        "services/tests/data/README%md",
        "Rows as `services/src/voting.rs` reads them.\n",
    )
    .unwrap();
    write(
        "services/tests/check.rs",
        "//! How: `tests/data/README%md`; the ICD: ../shared/ICD%md.\n",
    )
    .unwrap();
    write(
        "docs/a%md",
        "# A\n\n`services/src/voting.rs`, `services/src/gone.rs`, `fcc/health/<role>`,\n\
         `services/<NAME>.rs`, `target/venv`, `cargo test --workspace`, [b](b%md),\n\
         [a](a%md#a), [design](../DESIGN%md), [up](../../outside%md), `docs/icd%md`\n\n\
         ```sh\ncat services/src/missing-in-a-fence.rs `services/src/fenced.rs`\n```\n",
    )
    .unwrap();
    let (mut missing, checked) = dangling(&root);
    missing.sort();
    let _ = fs::remove_dir_all(&root);
    let expected = [
        "docs/a%md:3: `services/src/gone.rs` is not in the repository",
        "docs/a%md:4: link (b%md) leads to nothing in the repository",
        "docs/a%md:5: `docs/icd%md` is not in the repository",
        "docs/a%md:5: link (../../outside%md) leads to nothing in the repository",
        "docs/a%md:5: link (../DESIGN%md) leads to nothing in the repository",
        "services/src/voting.rs:1: cites DESIGN%md, which is not in the repository",
        "services/tests/check.rs:1: cites ../shared/ICD%md, which is not in the repository",
    ]
    .map(md);
    assert_eq!(missing, expected);
    // The data README's span, the four citations of the two sources, the four spans and the
    // four links of docs/a: 13.
    assert_eq!(checked, 13);
}

/// The source directories the module map of docs/design.md accounts for: every crate's sources
/// and the root package's (the fuzz targets' crate whole: its examples and tests too).
const MAPPED: &[&str] = &[
    "interfaces/src",
    "services/protocol/src",
    "services/flight/src",
    "services/ground/src",
    "linksim/src",
    "platform/src",
    "partitions/src",
    "gcs/src",
    "bridge/src",
    "clib/src",
    "fuzz-targets",
    "src",
];

/// docs/design.md's module map is true to the code: every Rust source file of the crates and
/// the root package is named in it, by its path or by a directory inside the sources that holds
/// it (`gcs/src/map/`; a crate's own directory, `gcs/`, names no module); a `lib.rs` or `mod.rs`
/// by a file beside it too (it only gathers them). Every workspace member of Cargo.toml is named
/// as a crate (`**`services/flight/`**`), the fuzz targets aside (`fuzz-targets` is a path of the map).
/// (That every path it names exists is [`every_path_a_document_names_is_in_the_repository`]'s.)
#[test]
fn the_module_map_names_every_module() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let design = fs::read_to_string(root.join("docs/design.md")).unwrap();
    let map = design
        .split("\n## Module map")
        .nth(1)
        .and_then(|rest| rest.split("\n## ").next())
        .expect("docs/design.md has a section \"Module map\"");
    let named: BTreeSet<String> = code_spans(&without_fences(map))
        .into_iter()
        .map(|(_, span)| span)
        .collect();
    let covered = |sources: &str, file: &Path| {
        let by_directory = file
            .ancestors()
            .skip(1)
            .take_while(|dir| dir.as_os_str().len() > sources.len())
            .any(|dir| named.contains(&format!("{}/", dir.display())));
        let gathering = file
            .file_name()
            .is_some_and(|n| n == "lib.rs" || n == "mod.rs");
        let sibling_named = file.parent().is_some_and(|dir| {
            named
                .iter()
                .any(|n| Path::new(n).parent() == Some(dir) && !n.ends_with('/'))
        });
        named.contains(&file.display().to_string()) || by_directory || (gathering && sibling_named)
    };
    let mut missing: Vec<String> = MAPPED
        .iter()
        .flat_map(|dir| {
            files(&root.join(dir))
                .into_iter()
                .map(move |f| (*dir, Path::new(dir).join(f)))
        })
        .filter(|(_, f)| f.extension().is_some_and(|e| e == "rs"))
        .filter(|(sources, f)| !covered(sources, f))
        .map(|(_, f)| f.display().to_string())
        .collect();
    missing.sort();
    let manifest = fs::read_to_string(root.join("Cargo.toml")).unwrap();
    let members = manifest
        .split("members = [")
        .nth(1)
        .and_then(|rest| rest.split(']').next())
        .expect("Cargo.toml lists the workspace members")
        .split(',')
        .map(|m| m.trim().trim_matches('"'))
        .filter(|m| !m.is_empty() && *m != "fuzz-targets");
    for member in members {
        if !map.contains(&format!("**`{member}/`**")) {
            missing.push(format!("the crate {member}/"));
        }
    }
    assert!(
        missing.is_empty(),
        "docs/design.md's module map does not name {} module(s):\n{}",
        missing.len(),
        missing.join("\n")
    );
}
