//! `cargo xtask kin …`: gimbal kinematics from the command line.
#[derive(clap::Args, Debug)]
pub struct KinArgs {}
pub fn run(_args: KinArgs) -> anyhow::Result<std::process::ExitCode> {
    anyhow::bail!("kin: being written")
}
