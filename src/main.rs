//! incise command-line entry point: parses the CLI and turns errors into exit code 1.

use std::process::ExitCode;

use clap::Parser;
use incise::cli::{Cli, Command, MeshCommand};
use incise::run::{RunOptions, run_scene};
use incise::{bench, compare, mesh_cmd, screenshots};

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
            screenshot_every,
            screenshot_size,
        } => run_scene(&RunOptions {
            scene,
            frames,
            out,
            vtu_every,
            threads,
            quiet,
            device,
            screenshot_every,
            screenshot_size,
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
        Command::Render {
            scene,
            frame,
            out,
            size,
            overlay,
            device,
        } => screenshots::render_frame(&scene, frame, &out, size, &overlay, device)
            .map(|()| println!("wrote {}", out.display())),
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
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}
