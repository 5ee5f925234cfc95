//! The JSON answer of the tool commands (`kin ik|fk`, `calib fit`,
//! `plan jump|compare`): one JSON value on a line of stdout, or
//! `{"error":"…"}` and exit status 1.

use std::io::Write;
use std::process::ExitCode;

use serde::Serialize;

#[derive(Serialize)]
struct ErrorOut<'a> {
    error: &'a str,
}

/// `{"error":"…"}` for `msg`.
pub(crate) fn error_json(msg: &str) -> String {
    serde_json::to_string(&ErrorOut { error: msg })
        .unwrap_or_else(|_| String::from(r#"{"error":"unprintable error"}"#))
}

/// Prints the JSON result line; errors as `{"error":"…"}` with exit 1.
pub(crate) fn emit(result: Result<String, String>) -> ExitCode {
    match result {
        Ok(json) => {
            println!("{json}");
            ExitCode::SUCCESS
        }
        Err(msg) => {
            println!("{}", error_json(&msg));
            ExitCode::FAILURE
        }
    }
}

/// Prints `value` as one JSON line.
pub(crate) fn print_json<T: Serialize>(value: &T) -> anyhow::Result<()> {
    let mut out = std::io::stdout().lock();
    serde_json::to_writer(&mut out, value)?;
    writeln!(out)?;
    Ok(())
}

/// Prints `{"error":"…"}` and answers exit status 1.
pub(crate) fn fail(msg: impl Into<String>) -> anyhow::Result<ExitCode> {
    Ok(emit(Err(msg.into())))
}
