//! incise command-line entry point: parses the CLI and turns errors into exit code 1.

use std::process::ExitCode;

use clap::Parser;
use incise::cli::{Cli, Command, ExperimentCommand, MeshCommand};
use incise::run::{RunOptions, run_scene};
use incise::{bench, compare, experiment, mesh_cmd};

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Run {
            scene,
            frames,
            out,
            vtu_every,
            threads,
            quiet,
            device,
        } => run_scene(&RunOptions {
            scene,
            frames,
            out,
            vtu_every,
            threads,
            quiet,
            device,
        })
        .map(|o| {
            let last = o.report.frames.last();
            println!(
                "completed {} frames of {}: {} tets released, max von Mises {:.0} Pa",
                o.report.frames.len(),
                o.report.scene,
                last.map_or(0, |f| f.stats.released_total),
                last.map_or(0.0, |f| f.stats.max_von_mises),
            );
            println!("report: {}", o.report_path.display());
        }),
        Command::Compare {
            scene,
            frames,
            threads,
            json,
        } => compare::run(&scene, frames, threads, json),
        Command::Mesh { command } => match command {
            MeshCommand::Check { file, json } => mesh_cmd::check(&file, json),
            MeshCommand::Gen { kind, out } => mesh_cmd::generate(kind, &out),
        },
        Command::Bench {
            json,
            frames,
            case,
            device,
            scaling,
        } => bench::run(case, frames, json, device, scaling),
        Command::Experiment { command } => match command {
            ExperimentCommand::Rheology { out, presets } => {
                experiment::rheology::run(&experiment::rheology::RheologyOptions { out, presets })
                    .map(|summary| print!("{summary}"))
            }
            ExperimentCommand::NakaoPlate { out } => {
                experiment::nakao::run(&experiment::nakao::NakaoOptions { out })
                    .map(|table| print!("{table}"))
            }
            ExperimentCommand::NakaoBench {
                loops,
                budget_ms,
                json,
            } => experiment::nakao_bench::run(&experiment::nakao_bench::NakaoBenchOptions {
                loops,
                budget_ms,
                json,
            }),
        },
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}
