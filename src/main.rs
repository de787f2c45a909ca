//! incise command-line entry point: parses the CLI and turns errors into exit code 1.

use std::process::ExitCode;

use clap::Parser;
use incise::bench::{self, realtime as bench_realtime, render as bench_render};
use incise::cli::{BenchTarget, Cli, Command, ExperimentCommand, MeshCommand, ScenesAction};
use incise::pictures::render_command;
use incise::preview;
use incise::run::run_scene;
use incise::scene::built_in;
use incise::sim_body::DeviceChoice;
use incise::{compare, exercise, experiment, mesh_cmd};

fn main() -> ExitCode {
    let cli = Cli::parse();
    let command = cli
        .command
        .unwrap_or_else(Command::default_for_this_machine);
    // The commands that stop gracefully on Ctrl-C (outputs written, exit 130 or a clean
    // XR session end); the others keep the default (the process dies).
    if matches!(
        command,
        Command::Run(_) | Command::Xr(_) | Command::Exercise { .. }
    ) {
        incise::interrupt::install();
    }
    let result = match command {
        Command::Run(args) => run_scene(&args.into()).map(|o| {
            println!("{}", o.report.summary());
            println!("report: {}", o.report_path.display());
        }),
        Command::Preview(args) => preview::run(args.into()),
        Command::Xr(args) => incise::xr::run(&args.into()).map(|summary| println!("{summary}")),
        Command::Render {
            scene,
            frame,
            out,
            size,
            overlay,
            device,
        } => render_command::render_frame(&scene, frame, &out, size, &overlay, device)
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
            target: BenchTarget::Render,
            json,
            frames,
            case,
            device,
            scaling,
            ..
        } => bench_render::run(frames, json, case, device, scaling),
        Command::Bench {
            target: BenchTarget::Realtime,
            json,
            frames,
            device,
            scene,
            threads,
            cpu_kernel,
            cpu_sweep,
            markdown,
            ..
        } => bench_realtime::run(
            &scene,
            device,
            (
                threads,
                cpu_kernel.map(Into::into),
                cpu_sweep.map(Into::into),
            ),
            frames,
            bench::BenchOutput::of(json, markdown),
        )
        .map(|()| {
            if markdown && device != DeviceChoice::Gpu {
                incise::xr::headset_bench::print(&scene);
            }
        }),
        Command::Bench {
            target: BenchTarget::Scene,
            json,
            frames,
            device,
            scene,
            markdown,
            ..
        } => bench::scene::run(
            &scene,
            device,
            frames,
            bench::BenchOutput::of(json, markdown),
        ),
        Command::Bench {
            target: BenchTarget::Solver,
            json,
            frames,
            case,
            device,
            scaling,
            markdown,
            ..
        } => bench::run(
            case,
            frames,
            bench::BenchOutput::of(json, markdown),
            device,
            scaling,
        ),
        Command::Soak {
            scene,
            seconds,
            device,
            out,
            markdown,
        } => incise::bench::soak::run(&incise::bench::soak::SoakOptions {
            scene,
            seconds,
            device,
            out: out.clone(),
        })
        .and_then(|r| incise::bench::soak::conclude(&r, &out, markdown)),
        Command::Exercise {
            exercise,
            reference_stroke: Some(file),
            tilt,
            ..
        } => exercise::write_reference_stroke(&exercise, &file, tilt).map(|()| {
            println!("wrote {}", file.display());
        }),
        Command::Exercise {
            exercise,
            stroke: Some(stroke),
            out,
            device,
            history,
            quiet,
            ..
        } => exercise::run_exercise(&exercise::ExerciseOptions {
            exercise,
            stroke,
            out,
            device,
            history: history.clone(),
            quiet,
        })
        .map(|a| {
            println!("{}", a.result.summary());
            println!("result: {}", a.result_path.display());
            println!("report: {}", a.html_path.display());
            println!("history: {}", history.display());
        }),
        Command::Exercise { .. } => Err(anyhow::anyhow!(
            "incise exercise needs --stroke FILE (or --reference-stroke FILE)"
        )),
        Command::Scenes { action: None } => {
            for (name, _, about) in built_in::scenes() {
                println!("{name:<32} {about}");
            }
            Ok(())
        }
        Command::Scenes {
            action: Some(ScenesAction::Export { dir }),
        } => built_in::export(&dir)
            .map(|n| println!("wrote {n} files to {}", dir.display()))
            .map_err(|e| anyhow::anyhow!("{}: {e}", dir.display())),
        Command::Doctor => {
            let checks = incise::doctor::checks();
            print!("{}", incise::doctor::report(&checks));
            if incise::doctor::headset_ready(&checks) {
                Ok(())
            } else {
                return ExitCode::FAILURE;
            }
        }
        Command::Results { history } => exercise::read_history(&history)
            .map(|entries| print!("{}", exercise::history_table(&entries))),
        Command::Experiment { command } => match command {
            ExperimentCommand::Rheology {
                out,
                presets,
                quick,
            } => experiment::rheology::run(&experiment::rheology::RheologyOptions {
                out,
                presets,
                quick,
            })
            .map(|summary| print!("{summary}")),
            ExperimentCommand::NakaoPlate { out, quick } => {
                experiment::nakao::run(&experiment::nakao::NakaoOptions { out, quick })
                    .map(|table| print!("{table}"))
            }
            ExperimentCommand::NakaoChest { out, loops } => {
                experiment::nakao_chest::run(&experiment::nakao_chest::NakaoChestOptions {
                    out,
                    loops,
                })
                .map(|table| print!("{table}"))
            }
            ExperimentCommand::SceneFigures { scenes, update } => {
                experiment::scene_figures::run(&scenes, update.as_deref())
                    .map(|table| print!("{table}"))
            }
            ExperimentCommand::Substeps {
                scenes,
                frames,
                update,
            } => experiment::substep_budget::run(&scenes, frames, update.as_deref())
                .map(|table| print!("{table}")),
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
        Err(e) if e.downcast_ref::<incise::interrupt::Interrupted>().is_some() => {
            eprintln!("{e:#}");
            ExitCode::from(incise::interrupt::EXIT_INTERRUPTED)
        }
        Err(e) if e.downcast_ref::<incise::xr::XrUnavailable>().is_some() => {
            // No usable OpenXR runtime or headset: not a failure of incise (exit 2).
            eprintln!("{e}");
            ExitCode::from(2)
        }
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}
