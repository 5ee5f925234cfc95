//! `cargo xtask calib …`: error-model fitting.
#[derive(clap::Args, Debug)]
pub struct CalibArgs {}
pub fn run(_args: CalibArgs) -> anyhow::Result<std::process::ExitCode> {
    anyhow::bail!("calib: being written")
}
