//! What the binaries share: where their output goes by default, and how they end when the reader
//! of their standard output has gone (`work-precision --quick | head -1`).

use std::error::Error;
use std::io;
use std::path::PathBuf;

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
}
