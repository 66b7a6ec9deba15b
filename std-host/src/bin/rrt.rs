//! The `rrt` command-line tool. Argument parsing and error reporting only;
//! the work is in `rrt_host::cli`.

use std::io::{self, Write};
use std::process::ExitCode;

use clap::Parser;
use rrt_host::cli::{Cli, CliError, run};

fn main() -> ExitCode {
    let cli = Cli::parse();
    // Ctrl-C or SIGTERM: remove the outputs' temporary files, keep the old
    // outputs.
    if let Err(e) = rrt_host::output::atomic::remove_on_interrupt() {
        eprintln!(
            "rrt: warning: cannot handle interruptions ({e}); an interrupted run may leave a temporary file"
        );
    }
    let stdout = io::stdout();
    let mut out = io::BufWriter::new(stdout.lock());
    let result = run(&cli, &mut out).and_then(|()| out.flush().map_err(CliError::from));
    match result {
        Ok(()) => ExitCode::SUCCESS,
        // A closed pipe (`rrt ray … | head`) is not an error worth reporting.
        Err(CliError::Io(e)) if e.kind() == io::ErrorKind::BrokenPipe => ExitCode::SUCCESS,
        Err(e) => {
            let mut msg = format!("rrt: {e}");
            let mut src = std::error::Error::source(&e);
            while let Some(s) = src {
                msg.push_str(&format!(": {s}"));
                src = s.source();
            }
            eprintln!("{msg}");
            ExitCode::FAILURE
        }
    }
}
