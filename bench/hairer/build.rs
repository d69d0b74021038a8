//! Compiles E. Hairer's DOP853 and DOPRI5, the Fortran right-hand sides and the C-callable driver
//! with `gfortran -O3` into the static library `libhairer.a`.
//!
//! Environment: `FC` names the Fortran compiler (default `gfortran`); `HAIRER_FFLAGS` adds flags
//! after `-O3` (for example `-march=native`, which then should be given to rustc as well through
//! `RUSTFLAGS="-C target-cpu=native"`, or the comparison is no longer like for like).
//!
//! Both codes define a function `HINIT` (the initial step size). The sources stay as published;
//! the symbol of DOP853's copy is renamed in its object file with `objcopy`, so that both codes can
//! be linked into one program.

use std::env;
use std::path::{Path, PathBuf};
use std::process::Command;

type BuildResult<T> = Result<T, String>;

fn main() -> BuildResult<()> {
    let out = PathBuf::from(env::var("OUT_DIR").map_err(|e| format!("OUT_DIR: {e}"))?);
    let fc = env::var("FC").unwrap_or_else(|_| "gfortran".to_string());
    let extra: Vec<String> = env::var("HAIRER_FFLAGS")
        .unwrap_or_default()
        .split_whitespace()
        .map(str::to_string)
        .collect();
    println!("cargo:rerun-if-env-changed=FC");
    println!("cargo:rerun-if-env-changed=HAIRER_FFLAGS");
    println!("cargo:rerun-if-changed=build.rs");

    let version = run_output(Command::new(&fc).arg("--version")).map_err(|e| {
        format!(
            "cannot run the Fortran compiler `{fc}` ({e}). This benchmark needs gfortran: \
             `apt-get install gfortran` (Debian/Ubuntu), `brew install gcc` (macOS), or set FC."
        )
    })?;
    let version = version
        .lines()
        .next()
        .unwrap_or("unknown")
        .trim()
        .to_string();

    // (source, object, fixed-form legacy code?)
    let sources = [
        ("fortran/dop853.f", "dop853.o", true),
        ("fortran/dopri5.f", "dopri5.o", true),
        ("fortran/rhs.f", "rhs.o", true),
        ("fortran/driver.f90", "driver.o", false),
    ];
    for (src, _, _) in &sources[..2] {
        if !std::path::Path::new(src).exists() {
            return Err(format!(
                "{src} is missing: Hairer's codes are not part of the repository. Get dop853.f and \
                 dopri5.f from http://www.unige.ch/~hairer/software.html and copy them into \
                 bench/hairer/fortran/ (README.md, \"The Fortran sources\")."
            ));
        }
    }
    let mut objects = Vec::new();
    for (src, obj, legacy) in sources {
        println!("cargo:rerun-if-changed={src}");
        let obj = out.join(obj);
        let mut cmd = Command::new(&fc);
        cmd.arg("-O3").args(&extra).arg("-fPIC");
        if legacy {
            // Hairer's codes use FORTRAN 77 DO loops ending on a labelled statement; -std=legacy
            // accepts them without warnings.
            cmd.arg("-std=legacy");
        }
        cmd.arg("-c").arg(src).arg("-o").arg(&obj);
        run(&mut cmd)?;
        objects.push(obj);
    }
    run(Command::new("objcopy")
        .arg("--redefine-sym")
        .arg("hinit_=dop853_hinit_")
        .arg(&objects[0]))
    .map_err(|e| format!("{e} (objcopy is part of binutils)"))?;

    let lib = out.join("libhairer.a");
    if lib.exists() {
        std::fs::remove_file(&lib).map_err(|e| format!("removing {}: {e}", lib.display()))?;
    }
    run(Command::new("ar").arg("crs").arg(&lib).args(&objects))?;

    println!("cargo:rustc-link-search=native={}", out.display());
    println!("cargo:rustc-link-lib=static=hairer");
    // The Fortran runtime (formatted WRITE in the codes' error messages).
    if let Ok(path) = run_output(Command::new(&fc).arg("-print-file-name=libgfortran.so")) {
        if let Some(dir) = Path::new(path.trim()).parent() {
            if dir.is_absolute() {
                println!("cargo:rustc-link-search=native={}", dir.display());
            }
        }
    }
    println!("cargo:rustc-link-lib=dylib=gfortran");

    let flags = std::iter::once("-O3".to_string())
        .chain(extra)
        .collect::<Vec<_>>()
        .join(" ");
    std::fs::write(
        out.join("fortran_info.rs"),
        format!(
            "/// The Fortran compiler's version line.\npub const COMPILER: &str = {version:?};\n\
             /// The optimisation flags the Fortran was compiled with.\npub const FLAGS: &str = {flags:?};\n"
        ),
    )
    .map_err(|e| format!("writing fortran_info.rs: {e}"))?;
    Ok(())
}

fn run(cmd: &mut Command) -> BuildResult<()> {
    let status = cmd
        .status()
        .map_err(|e| format!("cannot run {cmd:?}: {e}"))?;
    if status.success() {
        Ok(())
    } else {
        Err(format!("{cmd:?} failed with {status}"))
    }
}

fn run_output(cmd: &mut Command) -> BuildResult<String> {
    let out = cmd
        .output()
        .map_err(|e| format!("cannot run {cmd:?}: {e}"))?;
    if out.status.success() {
        Ok(String::from_utf8_lossy(&out.stdout).into_owned())
    } else {
        Err(format!("{cmd:?} failed with {}", out.status))
    }
}
