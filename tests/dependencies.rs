//! Every declared dependency is used: a crate in a package's `[dependencies]` is named
//! in its code (`name::`, `use name`, `extern crate name`) or forwarded a feature by
//! `[features]`; a `[dev-dependencies]` one in its code or tests; a
//! `[build-dependencies]` one in `build.rs`. What cargo-machete checks, with no tool
//! to install: a dependency nothing uses still compiles into every build (issue 66
//! found thirteen, four of them in the emulator).

use std::path::{Path, PathBuf};

/// The workspace's root.
fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("deploy/ has a parent")
        .to_path_buf()
}

/// The text of every `.rs` file under `dir` (none if it does not exist).
fn rust_text(dir: &Path, out: &mut String) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries.flatten() {
        let p = e.path();
        if p.is_dir() {
            rust_text(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push_str(&std::fs::read_to_string(&p).unwrap_or_default());
            out.push('\n');
        }
    }
}

/// Whether code `text` names the library `lib`.
fn names(text: &str, lib: &str) -> bool {
    let word = |i: usize| {
        i == 0 || !text.as_bytes()[i - 1].is_ascii_alphanumeric() && text.as_bytes()[i - 1] != b'_'
    };
    [
        format!("{lib}::"),
        format!("use {lib}"),
        format!("extern crate {lib}"),
    ]
    .iter()
    .any(|needle| text.match_indices(needle.as_str()).any(|(i, _)| word(i)))
}

/// The unused dependencies of the package whose manifest is in `dir`, as
/// `table: name`; `tests` are its test folders beyond `tests/` and `benches/`.
fn unused(dir: &Path, tests: &[PathBuf]) -> Vec<String> {
    let manifest = std::fs::read_to_string(dir.join("Cargo.toml")).expect("a manifest");
    let manifest: toml::Table = manifest.parse().expect("a manifest that parses");
    let mut code = String::new();
    rust_text(&dir.join("src"), &mut code);
    let mut all = code.clone();
    for t in
        tests
            .iter()
            .cloned()
            .chain([dir.join("tests"), dir.join("benches"), dir.join("examples")])
    {
        rust_text(&t, &mut all);
    }
    let build = std::fs::read_to_string(dir.join("build.rs")).unwrap_or_default();
    let features = manifest
        .get("features")
        .map(|f| f.to_string())
        .unwrap_or_default();
    let mut out = Vec::new();
    for (table, text) in [
        ("dependencies", &code),
        ("dev-dependencies", &all),
        ("build-dependencies", &build),
    ] {
        let Some(deps) = manifest.get(table).and_then(|d| d.as_table()) else {
            continue;
        };
        for name in deps.keys() {
            let lib = name.replace('-', "_");
            let forwarded = features.contains(&format!("\"{name}/"))
                || features.contains(&format!("\"dep:{name}\""));
            if !names(text, &lib) && !forwarded {
                out.push(format!("{table}: {name}"));
            }
        }
    }
    out
}

/// Every package of the workspace, with the test folders its manifest adds.
fn packages() -> Vec<(PathBuf, Vec<PathBuf>)> {
    let ws: toml::Table = std::fs::read_to_string(root().join("Cargo.toml"))
        .expect("the workspace manifest")
        .parse()
        .expect("a manifest that parses");
    let members = ws["workspace"]["members"].as_array().expect("members");
    members
        .iter()
        .filter_map(|m| m.as_str())
        .map(|m| {
            let dir = root().join(m);
            // The `tactile` package's integration tests are the top-level tests/.
            let tests = if m == "deploy" {
                vec![root().join("tests")]
            } else {
                vec![]
            };
            (dir, tests)
        })
        .collect()
}

#[test]
fn every_declared_dependency_is_used() {
    let mut found = Vec::new();
    for (dir, tests) in packages() {
        for u in unused(&dir, &tests) {
            found.push(format!(
                "{}: {u}",
                dir.strip_prefix(root()).unwrap_or(&dir).display()
            ));
        }
    }
    assert!(
        found.is_empty(),
        "declared and not used:\n{}",
        found.join("\n")
    );
}

/// The check finds a dependency planted in a package that does not use it, and
/// takes the same package once its code names it.
#[test]
fn the_check_finds_a_planted_dependency() {
    let dir = tempfile::tempdir().expect("a temp dir");
    std::fs::create_dir(dir.path().join("src")).expect("src");
    std::fs::write(
        dir.path().join("Cargo.toml"),
        "[package]\nname = \"planted\"\n\n[dependencies]\nserde = \"1\"\nrand-core = \"0.9\"\n\n[features]\nfast = [\"rand-core/std\"]\n",
    )
    .expect("manifest");
    std::fs::write(dir.path().join("src/lib.rs"), "pub fn f() {}\n").expect("lib");
    assert_eq!(unused(dir.path(), &[]), ["dependencies: serde"]);
    std::fs::write(dir.path().join("src/lib.rs"), "use serde::Serialize;\n").expect("lib");
    assert!(unused(dir.path(), &[]).is_empty());
    // A name inside a longer one is no use of it.
    std::fs::write(dir.path().join("src/lib.rs"), "use my_serde::Serialize;\n").expect("lib");
    assert_eq!(unused(dir.path(), &[]), ["dependencies: serde"]);
}
