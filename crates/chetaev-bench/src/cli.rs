//! What the binaries share: where their output goes, how they print their summary, and how they
//! end, also when the reader of their standard output has gone (`work-precision --quick | head -1`).

use std::error::Error;
use std::io::{self, Write};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// The folder a binary writes into when no `--out` is given: `chetaev-bench-out/<binary>` under
/// the current directory, never the source tree (the committed `docs/performance` is regenerated
/// only with an explicit `--out docs/performance`).
pub fn default_out(binary: &str) -> PathBuf {
    PathBuf::from("chetaev-bench-out").join(binary)
}

/// Whether `e` is a write to a pipe whose reader has gone. Rust ignores `SIGPIPE`, so such a
/// write fails with [`io::ErrorKind::BrokenPipe`]; a binary treats it as the end of its output
/// and exits with success, as `cat` and `ls` do.
pub fn is_broken_pipe(e: &(dyn Error + 'static)) -> bool {
    e.downcast_ref::<io::Error>()
        .is_some_and(|e| e.kind() == io::ErrorKind::BrokenPipe)
}

/// The folder a binary writes into, `out` or else [`default_out`] of `binary`, created (and made
/// absolute where it can be, so the summary names it unambiguously).
pub fn output_dir(out: Option<PathBuf>, binary: &str) -> Result<PathBuf, Box<dyn Error>> {
    let out = out.unwrap_or_else(|| default_out(binary));
    std::fs::create_dir_all(&out)
        .map_err(|e| format!("cannot create the output directory {}: {e}", out.display()))?;
    Ok(out.canonicalize().unwrap_or(out))
}

/// Prints a binary's summary on standard output and where its files were written. The files are
/// written first: a reader that leaves early only shortens this summary.
pub fn print_summary(summary: &str, out: &Path) -> Result<(), Box<dyn Error>> {
    let mut stdout = io::stdout().lock();
    write!(stdout, "{summary}")?;
    writeln!(stdout, "written to {}", out.display())?;
    stdout.flush()?;
    Ok(())
}

/// Ends the binary on an argument that was read but makes no sense (`--n 0`, `--hi inf`), as clap
/// ends it on one that cannot be read: the message and the usage on standard error, exit status 2.
/// Errors of the run itself (a file that cannot be written) exit with status 1 through [`exit`].
pub fn refuse_argument<C: clap::CommandFactory>(message: impl std::fmt::Display) -> ! {
    C::command()
        .error(clap::error::ErrorKind::ValueValidation, message)
        .exit()
}

/// How the binary `binary` ends after `result`: success, also when the reader of its output has
/// gone ([`is_broken_pipe`]); otherwise the error on standard error, after the binary's name.
pub fn exit(binary: &str, result: Result<(), Box<dyn Error>>) -> ExitCode {
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) if is_broken_pipe(e.as_ref()) => ExitCode::SUCCESS,
        Err(e) => {
            let _ = writeln!(io::stderr(), "{binary}: {e}");
            ExitCode::FAILURE
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn output_goes_under_the_current_directory() {
        let out = default_out("ensemble");
        assert!(out.is_relative());
        assert_eq!(out, PathBuf::from("chetaev-bench-out/ensemble"));
    }

    #[test]
    fn a_broken_pipe_is_recognised_through_a_box() {
        let e: Box<dyn Error> = io::Error::from(io::ErrorKind::BrokenPipe).into();
        assert!(is_broken_pipe(e.as_ref()));
        let e: Box<dyn Error> = io::Error::from(io::ErrorKind::NotFound).into();
        assert!(!is_broken_pipe(e.as_ref()));
        let e: Box<dyn Error> = "broken pipe".into();
        assert!(!is_broken_pipe(e.as_ref()));
    }

    #[test]
    fn a_binary_fails_on_an_error_and_not_on_a_closed_pipe() {
        assert_eq!(exit("test", Ok(())), ExitCode::SUCCESS);
        let pipe: Box<dyn Error> = io::Error::from(io::ErrorKind::BrokenPipe).into();
        assert_eq!(exit("test", Err(pipe)), ExitCode::SUCCESS);
        assert_eq!(exit("test", Err("no such scene".into())), ExitCode::FAILURE);
    }

    #[test]
    fn the_output_folder_is_created() -> Result<(), Box<dyn Error>> {
        let root = std::env::temp_dir().join(format!("chetaev-bench-cli-{}", std::process::id()));
        let dir = root.join("a/b");
        let made = output_dir(Some(dir.clone()), "test")?;
        assert!(made.is_dir() && made.is_absolute(), "{}", made.display());
        assert_eq!(made, dir.canonicalize()?);
        std::fs::remove_dir_all(&root)?;
        Ok(())
    }
}
