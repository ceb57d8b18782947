//! The `fxrt` executable: parses the command line and dispatches to `fxrt::cli::run`. Exit
//! codes: 0 done, 1 a mismatch was found, 2 bad input (one line on stderr naming the file or
//! parameter).

use clap::Parser;
use fxrt::cli::{Cli, error_line, run};
use std::process::ExitCode;

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(c) => c,
        Err(e) if matches!(e.kind(), clap::error::ErrorKind::DisplayHelp | clap::error::ErrorKind::DisplayVersion) => {
            e.exit()
        }
        Err(e) => {
            eprintln!("fxrt: {}", error_line(&e));
            return ExitCode::from(2);
        }
    };
    match run::run(cli.command_or_default()) {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => ExitCode::from(1),
        Err(e) => {
            eprintln!("fxrt: {e}");
            ExitCode::from(2)
        }
    }
}
