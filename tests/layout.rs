//! The workspace draws the architecture, and keeps drawing it: no module imports a
//! module that imports it back, no source file outgrows a read, and the crates that
//! must not depend on each other do not (`cargo tree -e normal`); the Verilog ships in
//! the crate that compiles it.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::process::Command;

/// The workspace's root.
fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("deploy/ has a parent")
        .to_path_buf()
}

/// Every crate's `src/` folder.
fn crate_sources() -> Vec<PathBuf> {
    let mut out = Vec::new();
    for top in ["common", "master", "network-emulator", "slave", "deploy"] {
        let dir = root().join(top);
        for d in [dir.clone()].into_iter().chain(
            std::fs::read_dir(&dir)
                .expect("folder")
                .flatten()
                .map(|e| e.path()),
        ) {
            if d.join("Cargo.toml").is_file() && d.join("src").is_dir() {
                out.push(d.join("src"));
            }
        }
    }
    out
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).expect("source folder").flatten() {
        let p = e.path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// A file's module path within its crate: `src/a/b.rs` and `src/a/b/mod.rs` are `a::b`.
fn module_of(src: &Path, file: &Path) -> Vec<String> {
    let rel = file
        .strip_prefix(src)
        .expect("inside src")
        .with_extension("");
    let mut parts: Vec<String> = rel.iter().map(|c| c.to_string_lossy().into()).collect();
    if matches!(
        parts.last().map(String::as_str),
        Some("mod" | "lib" | "main")
    ) {
        parts.pop();
    }
    parts
}

/// Strips `//` comments (docs name modules without importing them).
fn code(text: &str) -> String {
    text.lines()
        .map(|l| l.split("//").next().unwrap_or(""))
        .collect::<Vec<_>>()
        .join("\n")
}

/// The modules of `text` named by `crate::a::b...` and `super::x`: the longest prefix
/// of each path that is a module of the crate.
fn references(me: &[String], text: &str, modules: &BTreeSet<Vec<String>>) -> BTreeSet<Vec<String>> {
    let mut out = BTreeSet::new();
    let word = |c: char| c.is_ascii_alphanumeric() || c == '_' || c == ':';
    for (anchor, base) in [
        ("crate::", Vec::new()),
        ("super::", me[..me.len().saturating_sub(1)].to_vec()),
    ] {
        for (at, _) in text.match_indices(anchor) {
            if at > 0 && text[..at].ends_with(|c: char| c.is_ascii_alphanumeric() || c == '_') {
                continue;
            }
            let rest: String = text[at + anchor.len()..]
                .chars()
                .take_while(|&c| word(c))
                .collect();
            let mut path = base.clone();
            path.extend(rest.split("::").filter(|s| !s.is_empty()).map(String::from));
            while !path.is_empty() && !modules.contains(&path) {
                path.pop();
            }
            out.insert(path);
        }
    }
    out
}

/// The module graph of one crate: who names whom, a module's own ancestors and
/// descendants left out (a parent declares its children; a child may use its parent).
fn graph(src: &Path) -> BTreeMap<Vec<String>, BTreeSet<Vec<String>>> {
    let mut files = Vec::new();
    rust_files(src, &mut files);
    let texts: BTreeMap<Vec<String>, String> = files
        .iter()
        .map(|f| {
            (
                module_of(src, f),
                code(&std::fs::read_to_string(f).expect("readable")),
            )
        })
        .collect();
    let modules: BTreeSet<Vec<String>> = texts.keys().cloned().collect();
    texts
        .iter()
        .map(|(me, text)| {
            let deps = references(me, text, &modules)
                .into_iter()
                .filter(|d| !d.starts_with(me) && !me.starts_with(d))
                .collect();
            (me.clone(), deps)
        })
        .collect()
}

/// A cycle through `from`, if any (depth-first search back to it).
fn cycle_through(
    g: &BTreeMap<Vec<String>, BTreeSet<Vec<String>>>,
    from: &Vec<String>,
) -> Option<Vec<Vec<String>>> {
    let mut stack = vec![(from.clone(), vec![from.clone()])];
    let mut seen = BTreeSet::new();
    while let Some((at, path)) = stack.pop() {
        for next in g.get(&at).into_iter().flatten() {
            if next == from {
                return Some(path);
            }
            if seen.insert(next.clone()) {
                let mut p = path.clone();
                p.push(next.clone());
                stack.push((next.clone(), p));
            }
        }
    }
    None
}

#[test]
fn no_module_imports_a_module_that_imports_it_back() {
    let mut cycles = Vec::new();
    for src in crate_sources() {
        let g = graph(&src);
        for m in g.keys() {
            if let Some(c) = cycle_through(&g, m) {
                let names: Vec<String> = c.iter().map(|p| p.join("::")).collect();
                cycles.push(format!("{}: {}", src.display(), names.join(" -> ")));
            }
        }
    }
    assert!(cycles.is_empty(), "import cycles:\n{}", cycles.join("\n"));
}

#[test]
fn the_cycle_check_sees_a_cycle() {
    let dir = tempfile::tempdir().expect("temp dir");
    std::fs::write(dir.path().join("lib.rs"), "mod a;\nmod b;\n").expect("write");
    std::fs::write(dir.path().join("a.rs"), "use crate::b::B;\npub struct A;\n").expect("write");
    std::fs::write(dir.path().join("b.rs"), "pub struct B(crate::a::A);\n").expect("write");
    let g = graph(dir.path());
    assert!(cycle_through(&g, &vec!["a".to_string()]).is_some(), "{g:?}");
    std::fs::write(dir.path().join("b.rs"), "pub struct B;\n").expect("write");
    let g = graph(dir.path());
    assert!(cycle_through(&g, &vec!["a".to_string()]).is_none(), "{g:?}");
}

#[test]
fn no_source_file_outgrows_a_read() {
    let mut long = Vec::new();
    for src in crate_sources() {
        let mut files = Vec::new();
        rust_files(&src, &mut files);
        for f in files {
            let n = std::fs::read_to_string(&f)
                .expect("readable")
                .lines()
                .count();
            if n > 600 {
                long.push(format!("{} ({n} lines)", f.display()));
            }
        }
    }
    assert!(
        long.is_empty(),
        "source files over 600 lines:\n{}",
        long.join("\n")
    );
}

/// The packages in `package`'s normal dependency tree (all features).
fn tree(package: &str) -> String {
    let out = Command::new(env!("CARGO"))
        .current_dir(root())
        .args([
            "tree",
            "--locked",
            "--offline",
            "--all-features",
            "-e",
            "normal",
        ])
        .args(["--prefix", "none", "-p", package])
        .output()
        .expect("cargo tree runs");
    assert!(
        out.status.success(),
        "cargo tree -p {package}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

fn has(tree: &str, package: &str) -> bool {
    tree.lines()
        .any(|l| l.split_whitespace().next() == Some(package))
}

#[test]
fn the_crates_depend_as_the_architecture_says() {
    let math = tree("tactile-math");
    for other in [
        "iceoryx2",
        "rustix",
        "zenoh",
        "tactile-messages",
        "tactile-scenario",
    ] {
        assert!(
            !has(&math, other),
            "tactile-math depends on {other}:\n{math}"
        );
    }
    let master = tree("tactile-master");
    assert!(
        !has(&master, "tactile-netem"),
        "the master links the netem models"
    );
    let slave = tree("tactile-slave");
    assert!(
        !has(&slave, "tactile-netem"),
        "the slave links the netem models"
    );
    let emulator = tree("tactile-network-emulator");
    assert!(
        !has(&emulator, "tactile-control"),
        "the emulator links the control"
    );
    assert!(has(&emulator, "tactile-netem") && has(&master, "tactile-control"));
    let messages = tree("tactile-messages");
    assert!(
        has(&messages, "iceoryx2"),
        "messages is the crate deriving iceoryx2's types"
    );
    for pure in ["tactile-scenario", "tactile-control", "tactile-netem"] {
        let t = tree(pure);
        for other in ["zenoh", "tactile-runtime", "tactile-transport"] {
            assert!(!has(&t, other), "{pure} depends on {other}");
        }
    }
    // The report reads records: it needs none of the nodes, their runtime or links.
    let report = tree("tactile-report");
    for node in [
        "tactile-master",
        "tactile-slave",
        "tactile-network-emulator",
        "tactile-runtime",
        "tactile-transport",
        "tactile-devices",
    ] {
        assert!(!has(&report, node), "tactile-report depends on {node}");
    }
    assert!(has(&report, "tactile-records"));
    // The records and the links stand below the runtime, not beside it.
    for low in ["tactile-records", "tactile-transport", "tactile-devices"] {
        let t = tree(low);
        assert!(!has(&t, "tactile-runtime"), "{low} depends on the runtime");
    }
    // Launching and sweeping are a library the command and the Python package both
    // call: neither it nor the Python package builds the command's crate (its clap
    // arguments, its developer tooling).
    for lib in ["tactile-launch", "tactile-py"] {
        let t = tree(lib);
        assert!(
            has(&t, "tactile-launch"),
            "{lib} does not have tactile-launch"
        );
        assert!(
            !has(&t, "tactile"),
            "{lib} depends on the command's crate:\n{t}"
        );
    }
    // The nodes own their peripherals: the runtime drives them through
    // tactile-peripheral's traits and knows no device, arm or gimbal.
    let runtime = tree("tactile-runtime");
    for node_side in ["tactile-devices", "tactile-chain"] {
        assert!(
            !has(&runtime, node_side),
            "tactile-runtime depends on {node_side}"
        );
    }
}

/// The per-sample protocol is the driver's alone: no node crate names the pacer, the
/// run filter, a control message (probe, end, waiting, dropped; their bits have no
/// public name, `Control` makes them), or the record's once-a-second counters.
#[test]
fn only_the_driver_speaks_the_protocol() {
    let words = [
        "Pacer",
        "RunFilter",
        "Control::",
        "recv_paced",
        "counters_due",
    ];
    for krate in ["master", "network-emulator", "slave"] {
        let mut files = Vec::new();
        rust_files(&root().join(krate).join("src"), &mut files);
        for f in files {
            let text = code(&std::fs::read_to_string(&f).expect("source"));
            for w in words {
                assert!(!text.contains(w), "{} names {w}", f.display());
            }
        }
    }
}

/// The paths a file's `include_str!`/`include_bytes!` name, resolved from its folder.
fn included(file: &Path) -> Vec<PathBuf> {
    let text = std::fs::read_to_string(file).expect("readable");
    let mut out = Vec::new();
    for macro_ in ["include_str!(\"", "include_bytes!(\""] {
        for (at, _) in text.match_indices(macro_) {
            let rest = &text[at + macro_.len()..];
            let path = &rest[..rest.find('"').expect("closing quote")];
            out.push(file.parent().expect("folder").join(path));
        }
    }
    out
}

/// The Verilog lives beside the crate that carries and compiles it, so the crate's
/// package (`cargo package` takes the crate's folder alone) builds on its own: every
/// file `tactile-rtl` includes is inside `common/rtl/`.
#[test]
fn the_verilog_ships_with_the_crate_that_compiles_it() {
    let krate = root()
        .join("common/rtl")
        .canonicalize()
        .expect("common/rtl");
    let mut files = Vec::new();
    rust_files(&krate.join("src"), &mut files);
    files.push(krate.join("build.rs"));
    let mut outside = Vec::new();
    let mut verilog = 0;
    for f in &files {
        for p in included(f) {
            let p = p
                .canonicalize()
                .unwrap_or_else(|e| panic!("{}: {e}", p.display()));
            verilog += usize::from(p.extension().is_some_and(|x| x == "v" || x == "vh"));
            if !p.starts_with(&krate) {
                outside.push(format!("{} includes {}", f.display(), p.display()));
            }
        }
    }
    assert!(verilog >= 25, "{verilog} Verilog files included");
    assert!(
        outside.is_empty(),
        "included from outside the crate:\n{}",
        outside.join("\n")
    );
    let build = std::fs::read_to_string(krate.join("build.rs")).expect("build.rs");
    assert!(
        build.contains("rerun-if-changed=hdl\""),
        "build.rs watches hdl/"
    );
}
