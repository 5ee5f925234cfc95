//! `cargo xtask plan …`: galvo jump planning.
#[derive(clap::Args, Debug)]
pub struct PlanArgs {}
pub fn run(_args: PlanArgs) -> anyhow::Result<std::process::ExitCode> {
    anyhow::bail!("plan: being written")
}
