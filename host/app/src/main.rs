//! `shadow-zoo`: render, list and compare shadow techniques.

use std::process::ExitCode;

use clap::Parser;

fn main() -> ExitCode {
    env_logger::Builder::from_env(
        env_logger::Env::default().default_filter_or("warn,wgpu_hal::gles::egl=off"),
    )
    .init();
    // Plugin panics are caught and reported as errors; keep the hook from printing them twice.
    std::panic::set_hook(Box::new(|info| log::debug!("{info}")));
    let cli = shadow_zoo::cli::Cli::parse();
    match shadow_zoo::commands::run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}
