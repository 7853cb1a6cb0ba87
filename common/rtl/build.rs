//! With the feature `verilator`: writes the RTL for one format and geometry (from the
//! model, as `tactile hdl rtl` does), has Verilator turn each module into C++, and
//! compiles that, the glue (`src/glue.cpp`) and Verilator's runtime into this crate.
//!
//! The format and geometry: `TACTILE_RTL_WORD`, `TACTILE_RTL_FRAC`,
//! `TACTILE_RTL_ROUNDING` (`nearest`, `truncate`) and `TACTILE_RTL_DEVICE` (`paper`,
//! `omni`); by default the paper's `[s16.13]`, nearest, and its geometry. A run whose
//! scenario asks for another is refused with these variables named.
//!
//! The pipeline: `TACTILE_RTL_PIPELINE` (`sample`, `unit`, `module`), by default
//! `module`, the paper's architecture: a sample takes one clock of each module, so the
//! simulator evaluates each module's logic once a sample (the deeper pipelines give the
//! same bits in more clocks, each evaluating the whole module again).
//!
//! Verilator's options: `TACTILE_RTL_VERILATOR_ARGS`, appended to ours (`-O3`, C++ at
//! `-O2`), so that each can be measured by the bench (docs/09 gives what each costs).
//!
//! Under `cargo clippy`, which links nothing, the models' C++ is not compiled (the
//! cfg is still set, so the simulation's Rust is linted).
//!
//! Without Verilator on `PATH` the crate still builds (a new user's `cargo test
//! --workspace --all-features` needs only Rust): the build script warns, leaves out
//! the cfg `tactile_rtl_sim`, and `arithmetic = "rtl"` is refused at run time naming
//! the tool and its package. Under `CI=true` a missing Verilator fails the build, since
//! CI installs it and must not pass without the hardware.

fn main() {
    println!("cargo:rerun-if-changed=hdl");
    println!("cargo:rerun-if-changed=src/glue.cpp");
    println!("cargo:rerun-if-changed=src/text.rs");
    println!("cargo:rerun-if-env-changed=CI");
    println!("cargo::rustc-check-cfg=cfg(tactile_rtl_sim)");
    #[cfg(feature = "verilator")]
    verilate::build();
}

#[cfg(feature = "verilator")]
#[allow(dead_code)]
#[path = "src/text.rs"]
mod text;

#[cfg(feature = "verilator")]
mod verilate {
    use super::text;

    use std::path::{Path, PathBuf};
    use std::process::Command;
    use tactile_math::cordic::{Cordic, CordicConfig, Rounding};
    use tactile_math::geometry::Geometry;

    /// The modules simulated, each a Verilator model of its own (one `eval` per module).
    const TOPS: [&str; 4] = ["kin_fk", "kin_kff", "kin_fbf", "kin_ik"];

    fn env(name: &str, default: &str) -> String {
        println!("cargo:rerun-if-env-changed={name}");
        std::env::var(name).unwrap_or_else(|_| default.to_string())
    }

    fn fail(msg: String) -> ! {
        eprintln!("tactile-rtl: {msg}");
        std::process::exit(1);
    }

    pub fn build() {
        let out =
            PathBuf::from(std::env::var("OUT_DIR").unwrap_or_else(|_| fail("no OUT_DIR".into())));
        let rtl = out.join("rtl");
        write_rtl(&rtl);
        let Some(include) = verilator_include() else {
            return;
        };
        if linting_only() {
            println!("cargo:rustc-cfg=tactile_rtl_sim");
            return;
        }
        for top in TOPS {
            verilate(&rtl, &out, top);
        }
        let mut glue = cc::Build::new();
        glue.cpp(true)
            .file("src/glue.cpp")
            .include(&include)
            .include(include.join("vltstd"))
            .flag_if_supported("-std=c++17")
            .warnings(false);
        for top in TOPS {
            glue.include(out.join(top));
        }
        glue.compile("tactile_rtl_glue");
        for top in TOPS {
            println!("cargo:rustc-link-search=native={}", out.join(top).display());
            println!("cargo:rustc-link-lib=static=V{top}");
        }
        cc::Build::new()
            .cpp(true)
            .file(include.join("verilated.cpp"))
            .file(include.join("verilated_threads.cpp"))
            .include(&include)
            .include(include.join("vltstd"))
            .flag_if_supported("-std=c++17")
            .warnings(false)
            .compile("tactile_verilated");
        println!("cargo:rustc-link-lib=pthread");
        println!("cargo:rustc-link-lib=atomic");
        println!("cargo:rustc-cfg=tactile_rtl_sim");
    }

    /// True under `cargo clippy`, which checks and links nothing: the models' C++ (about
    /// 85 s of CI's two cores, and the test build compiles it again) is left out, and
    /// the simulation's Rust is still linted under its cfg. Cargo gives a build script
    /// the workspace's wrapper, which cargo-clippy sets to clippy-driver.
    fn linting_only() -> bool {
        println!("cargo:rerun-if-env-changed=RUSTC_WORKSPACE_WRAPPER");
        std::env::var_os("RUSTC_WORKSPACE_WRAPPER").is_some_and(|w| {
            Path::new(&w)
                .file_stem()
                .is_some_and(|s| s.to_string_lossy().starts_with("clippy-driver"))
        })
    }

    /// The RTL's files for the format and geometry asked for, into `dir`.
    fn write_rtl(dir: &Path) {
        let word: u32 = env("TACTILE_RTL_WORD", "16")
            .parse()
            .unwrap_or_else(|e| fail(format!("TACTILE_RTL_WORD: {e}")));
        let frac: u32 = env("TACTILE_RTL_FRAC", "13")
            .parse()
            .unwrap_or_else(|e| fail(format!("TACTILE_RTL_FRAC: {e}")));
        let rounding = match env("TACTILE_RTL_ROUNDING", "nearest").as_str() {
            "nearest" => Rounding::Nearest,
            "truncate" => Rounding::Truncate,
            other => fail(format!(
                "TACTILE_RTL_ROUNDING: {other:?} is not nearest or truncate"
            )),
        };
        let pipe = env("TACTILE_RTL_PIPELINE", "module");
        let pipeline = text::Pipeline::from_name(&pipe).unwrap_or_else(|| {
            fail(format!(
                "TACTILE_RTL_PIPELINE: {pipe:?} is not sample, unit or module"
            ))
        });
        let device = env("TACTILE_RTL_DEVICE", "paper");
        let geometry = Geometry::preset(&device).unwrap_or_else(|| {
            fail(format!(
                "TACTILE_RTL_DEVICE: {device:?} is not paper or omni"
            ))
        });
        let cfg = CordicConfig::new(word, frac, None, rounding)
            .unwrap_or_else(|e| fail(format!("bad fixed-point format: {e}")));
        let cordic =
            Cordic::new(cfg).unwrap_or_else(|e| fail(format!("bad fixed-point format: {e}")));
        let constants = cordic.rtl_constants();
        if let Some(a) = cordic.rtl_reduction_mismatch(&constants) {
            fail(format!("no RTL for [s{word}.{frac}]: its range reduction differs from the model's at {a:e}"));
        }
        std::fs::create_dir_all(dir).unwrap_or_else(|e| fail(format!("{}: {e}", dir.display())));
        for (name, text) in text::files(&constants, &geometry, pipeline) {
            std::fs::write(dir.join(name), text).unwrap_or_else(|e| fail(format!("{name}: {e}")));
        }
    }

    /// Verilator's include folder (`verilator --getenv VERILATOR_ROOT`), or `None`
    /// (with a warning) when Verilator cannot run outside CI: the crate then builds
    /// without the simulated modules.
    fn verilator_include() -> Option<PathBuf> {
        match Command::new("verilator")
            .args(["--getenv", "VERILATOR_ROOT"])
            .output()
        {
            Ok(out) if out.status.success() => {
                Some(PathBuf::from(String::from_utf8_lossy(&out.stdout).trim()).join("include"))
            }
            failed => {
                let why = match failed {
                    Ok(out) => format!("verilator --getenv exited with {}", out.status),
                    Err(e) => format!("cannot run verilator ({e})"),
                };
                if std::env::var("CI").is_ok_and(|v| v == "true") {
                    fail(format!("{why}: the feature rtl needs it (Debian: apt-get install verilator make g++)"));
                }
                println!("cargo:warning={why}: built without the RTL simulation, so arithmetic \"rtl\" is refused at run time (Debian: apt-get install verilator make g++, then cargo clean -p tactile-rtl and rebuild)");
                None
            }
        }
    }

    /// Verilator's C++ model of `top`, built into `out/top/libVtop.a`.
    fn verilate(rtl: &Path, out: &Path, top: &str) {
        let mdir = out.join(top);
        let mut cmd = Command::new("verilator");
        cmd.current_dir(rtl)
            .args([
                "--cc",
                "--build",
                "-O3",
                "-Wno-fatal",
                "-Wno-lint",
                "-Wno-style",
                // The stages pipe.vh makes combinational keep their non-blocking
                // assignments on purpose (one text for every pipeline): Verilator
                // makes them blocking, in the order written, which the RTL follows.
                "-Wno-COMBDLY",
                "-I.",
            ])
            .args([
                "--top-module",
                top,
                "--prefix",
                &format!("V{top}"),
                "--Mdir",
            ])
            .arg(&mdir)
            .args(["-CFLAGS", "-fPIC -O2", "-j", "2"])
            // Options to measure (docs/09, "The hardware in the loop"): after ours, so
            // a later -O or -CFLAGS -O wins.
            .args(env("TACTILE_RTL_VERILATOR_ARGS", "").split_whitespace())
            .args(text::MODULES);
        let status = cmd
            .status()
            .unwrap_or_else(|e| fail(format!("cannot run verilator: {e}")));
        if !status.success() {
            fail(format!("verilator failed on {top} ({status})"));
        }
        let archive = mdir.join(format!("V{top}__ALL.a"));
        std::fs::copy(&archive, mdir.join(format!("libV{top}.a")))
            .unwrap_or_else(|e| fail(format!("{}: {e}", archive.display())));
    }
}
