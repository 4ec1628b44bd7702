//! The walkthroughs in docs/architecture.md ("Adding a BSDF lobe", "a material kind", "a light
//! type", "a setting that reaches the shader") are true: every numbered item names files that
//! exist, and every name it quotes is defined in (or used by) one of the item's files. A rename or
//! a move that leaves a walkthrough behind fails here.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

const ROOTS: [&str; 6] = ["crates/", "shaders/", "tests/", "docs/", "src/", "bench/"];

/// The sections "### Adding …" of the document, by title, each as its numbered items (an item's
/// continuation lines joined to it).
fn walkthroughs(doc: &str) -> BTreeMap<String, Vec<String>> {
    let mut sections = BTreeMap::new();
    let mut current: Option<(String, Vec<String>)> = None;
    let mut in_item = false;
    for line in doc.lines() {
        if line.starts_with('#') {
            if let Some((title, items)) = current.take() {
                sections.insert(title, items);
            }
            current = line
                .strip_prefix("### Adding ")
                .map(|t| (t.to_string(), Vec::new()));
            in_item = false;
            continue;
        }
        let Some((_, items)) = current.as_mut() else {
            continue;
        };
        let numbered = line
            .split_once(". ")
            .filter(|(n, _)| !n.is_empty() && n.chars().all(|c| c.is_ascii_digit()));
        if let Some((n, rest)) = numbered {
            assert_eq!(
                n.parse::<usize>().ok(),
                Some(items.len() + 1),
                "items out of order at {line:?}"
            );
            items.push(rest.to_string());
            in_item = true;
        } else if in_item && line.starts_with("   ") {
            let item = items.last_mut().expect("an item to continue");
            item.push(' ');
            item.push_str(line.trim());
        } else {
            in_item = false;
        }
    }
    if let Some((title, items)) = current {
        sections.insert(title, items);
    }
    sections
}

/// The `quoted` spans of an item.
fn quoted(item: &str) -> Vec<&str> {
    item.split('`').skip(1).step_by(2).collect()
}

fn is_path(token: &str) -> bool {
    token.contains('/')
        || [".rs", ".wgsl", ".md", ".toml"]
            .iter()
            .any(|e| token.ends_with(e))
}

/// `token` as a word of `text`: not part of a longer identifier.
fn has_word(text: &str, word: &str) -> bool {
    let is_ident = |c: char| c.is_ascii_alphanumeric() || c == '_';
    text.match_indices(word).any(|(at, _)| {
        let before = text[..at].chars().next_back();
        let after = text[at + word.len()..].chars().next();
        !before.is_some_and(is_ident) && !after.is_some_and(is_ident)
    })
}

/// The words a quoted name must be found as: each `::` segment of an identifier, a flag's
/// field name, a label as it is written.
fn words(token: &str) -> Vec<String> {
    if let Some(flag) = token.strip_prefix("--") {
        return vec![flag.replace('-', "_")];
    }
    let ident = |s: &str| {
        !s.is_empty()
            && s.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
            && !s.starts_with(|c: char| c.is_ascii_digit())
    };
    if token.split("::").all(ident) {
        return token.split("::").map(str::to_string).collect();
    }
    vec![token.to_string()]
}

#[test]
fn the_architecture_walkthroughs_name_files_that_define_what_they_say() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let doc = std::fs::read_to_string(root.join("docs/architecture.md")).expect("the document");
    let sections = walkthroughs(&doc);
    for title in [
        "a BSDF lobe",
        "a material kind",
        "a light type",
        "a setting that reaches the shader",
    ] {
        assert!(
            sections.get(title).is_some_and(|items| items.len() >= 5),
            "docs/architecture.md has no walkthrough \"Adding {title}\" of numbered items"
        );
    }
    let mut checked = 0;
    for (title, items) in &sections {
        let mut folder = PathBuf::new();
        for (n, item) in items.iter().enumerate() {
            let at = format!("\"Adding {title}\", item {}", n + 1);
            let mut files = Vec::new();
            for token in quoted(item).into_iter().filter(|t| is_path(t)) {
                let path = if ROOTS.iter().any(|r| token.starts_with(r)) {
                    PathBuf::from(token)
                } else {
                    folder.join(token)
                };
                let text = std::fs::read_to_string(root.join(&path))
                    .unwrap_or_else(|e| panic!("{at}: {} names no file ({e})", path.display()));
                folder = path.parent().expect("a folder").to_path_buf();
                files.push(text);
            }
            assert!(!files.is_empty(), "{at} names no file");
            for token in quoted(item).into_iter().filter(|t| !is_path(t)) {
                for word in words(token) {
                    assert!(
                        files.iter().any(|text| has_word(text, &word)),
                        "{at}: `{token}` is not in the files it names"
                    );
                    checked += 1;
                }
            }
        }
    }
    assert!(checked > 40, "only {checked} names checked");
}

#[test]
fn a_walkthrough_that_names_a_missing_definition_fails() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let doc = "### Adding a thing\n\n1. `crates/core/src/light_kind.rs`: `NoSuchName`.\n";
    let sections = walkthroughs(doc);
    let item = &sections["a thing"][0];
    let text = std::fs::read_to_string(root.join("crates/core/src/light_kind.rs")).unwrap();
    assert!(!has_word(&text, "NoSuchName") && has_word(&text, "LightTag"));
    assert_eq!(
        quoted(item),
        ["crates/core/src/light_kind.rs", "NoSuchName"]
    );
    assert_eq!(words("LightKind::ALL"), ["LightKind", "ALL"]);
    assert_eq!(words("--clamp"), ["clamp"]);
}

/// The twin table of docs/architecture.md ("The estimator's twins") lists every WGSL file of the
/// estimator (each one in `crates/core/src`), with its Rust twin beside it.
#[test]
fn the_twin_table_lists_every_wgsl_file_of_the_estimator() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let doc = std::fs::read_to_string(root.join("docs/architecture.md")).expect("the document");
    let start = doc
        .find("| idea | WGSL | Rust twin |")
        .expect("the twin table");
    let mut listed = Vec::new();
    for row in doc[start..]
        .lines()
        .skip(2)
        .take_while(|l| l.starts_with('|'))
    {
        let cells: Vec<&str> = row.split('|').map(str::trim).collect();
        let wgsl = cells[2].trim_matches('`');
        // `folder/{a,b}.wgsl` names several files.
        match wgsl.split_once('{') {
            Some((folder, rest)) => {
                let (stems, ext) = rest.split_once('}').expect("a closing brace");
                listed.extend(stems.split(',').map(|s| format!("{folder}{s}{ext}")));
            }
            None => listed.push(wgsl.to_string()),
        }
    }
    let mut found = Vec::new();
    let mut folders = vec![root.join("crates/core/src")];
    while let Some(folder) = folders.pop() {
        for entry in std::fs::read_dir(&folder).expect("a folder") {
            let path = entry.expect("an entry").path();
            if path.is_dir() {
                folders.push(path);
            } else if path.extension().is_some_and(|e| e == "wgsl") {
                let relative = path.strip_prefix(root).expect("under the root");
                found.push(relative.to_string_lossy().replace('\\', "/"));
            }
        }
    }
    for file in &found {
        assert!(
            listed.contains(file),
            "{file} is missing from the twin table"
        );
        let twin = root.join(file).with_extension("rs");
        assert!(twin.exists(), "{file} has no Rust twin beside it");
    }
    for file in &listed {
        assert!(
            found.contains(file),
            "the twin table names {file}, which does not exist"
        );
    }
}
