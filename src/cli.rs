//! The `robosim` command line: the editor by default, `run` and `check` headless.
//! Every failure is one line on stderr and exit code 2.

use crate::db::{Database, Problem};
use crate::sim::Simulation;
use crate::sim::trace::Record;
use clap::{Parser, Subcommand, ValueEnum};
use pe::ContactSolver;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

#[derive(Debug, Parser)]
#[command(
    name = "robosim",
    version,
    about = "Design 2D robots from rigid polygons and watch them move"
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Option<Command>,
    /// The database folder the editor opens (default: the embedded one from data/).
    #[arg(long, global = false)]
    pub db: Option<PathBuf>,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Simulate a scene headless and write a trace.
    Run(RunArgs),
    /// Check a database and print every problem; exit 1 if any is an error.
    Check {
        /// The database folder (bodies.xml, robots.xml, scenes.xml).
        #[arg(long)]
        db: PathBuf,
    },
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Format {
    Jsonl,
    Csv,
}

#[derive(Debug, clap::Args)]
pub struct RunArgs {
    /// The database folder.
    #[arg(long)]
    pub db: PathBuf,
    /// The scene's name.
    #[arg(long)]
    pub scene: String,
    /// How many steps to simulate.
    #[arg(long, default_value_t = 1000)]
    pub steps: u64,
    /// The step in seconds (default: the scene's `timestep`, else 0.05).
    #[arg(long)]
    pub dt: Option<f64>,
    /// The contact solver: auto, exact, soft, thesis or sequential (default: the scene's,
    /// else auto).
    #[arg(long, value_parser = parse_solver)]
    pub solver: Option<ContactSolver>,
    /// Let bodies at rest sleep (skipped until something wakes them): faster, and the
    /// trace shows them exactly still.
    #[arg(long)]
    pub sleep: bool,
    /// Write a record every K steps (and at step 0 and the last step).
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u64).range(1..))]
    pub every: u64,
    /// The trace format (default: csv if --out ends in .csv, else jsonl).
    #[arg(long, value_enum)]
    pub format: Option<Format>,
    /// Write the trace to this file instead of stdout.
    #[arg(long)]
    pub out: Option<PathBuf>,
}

fn parse_solver(name: &str) -> Result<ContactSolver, String> {
    ContactSolver::from_name(name).ok_or_else(|| {
        let names: Vec<_> = ContactSolver::ALL.iter().map(|s| s.name()).collect();
        format!("unknown solver \"{name}\" (one of {})", names.join(", "))
    })
}

/// What opening the editor says in a build without the `app` feature.
pub const NO_EDITOR: &str =
    "robosim was built without the editor (feature `app`); use `robosim run` / `robosim check`";

/// A failure to report: one line, exit code 2.
pub struct Failure(pub String);

/// Runs the CLI with `args`; `open_editor` is called when no subcommand is given.
pub fn main(
    args: impl IntoIterator<Item = std::ffi::OsString>,
    open_editor: impl FnOnce(Option<PathBuf>) -> Result<(), String>,
) -> ExitCode {
    let cli = match Cli::try_parse_from(args) {
        Ok(cli) => cli,
        Err(e) if !e.use_stderr() => {
            // --help, --version
            let _ = e.print();
            return ExitCode::SUCCESS;
        }
        Err(e) => {
            let text = e.render().to_string();
            let line = text
                .lines()
                .next()
                .unwrap_or("bad arguments")
                .trim_start_matches("error: ");
            eprintln!("robosim: {line}");
            return ExitCode::from(2);
        }
    };
    let result = match cli.command {
        None => open_editor(cli.db)
            .map(|()| ExitCode::SUCCESS)
            .map_err(Failure),
        Some(Command::Check { db }) => check(&db),
        Some(Command::Run(args)) => run(&args),
    };
    match result {
        Ok(code) => code,
        Err(Failure(message)) => {
            eprintln!("robosim: {message}");
            ExitCode::from(2)
        }
    }
}

fn require_dir(db: &Path) -> Result<(), Failure> {
    if db.is_dir() {
        Ok(())
    } else {
        Err(Failure(format!("{}: not a database folder", db.display())))
    }
}

/// `robosim check`: every problem, one per line; exit 1 on errors.
pub fn check(db: &Path) -> Result<ExitCode, Failure> {
    require_dir(db)?;
    let (database, problems) = Database::load(db);
    for p in &problems {
        println!("{p}");
    }
    let errors = problems.iter().filter(|p| p.is_error()).count();
    let warnings = problems.len() - errors;
    let m = &database.model;
    println!(
        "{}: {} bodies, {} robots, {} scenes; {errors} errors, {warnings} warnings",
        db.display(),
        m.bodies.len(),
        m.robots.len(),
        m.scenes.len()
    );
    Ok(if errors > 0 {
        ExitCode::from(1)
    } else {
        ExitCode::SUCCESS
    })
}

/// `robosim run`.
pub fn run(args: &RunArgs) -> Result<ExitCode, Failure> {
    require_dir(&args.db)?;
    let (database, problems) = Database::load(&args.db);
    let errors: Vec<&Problem> = problems.iter().filter(|p| p.is_error()).collect();
    if let Some(first) = errors.first() {
        let more = if errors.len() > 1 {
            format!(" (and {} more: see robosim check)", errors.len() - 1)
        } else {
            String::new()
        };
        return Err(Failure(format!("{first}{more}")));
    }
    if let Some(dt) = args.dt
        && !dt.is_finite()
    {
        return Err(Failure(format!(
            "--dt {dt} is not a finite number of seconds"
        )));
    }
    let mut sim = Simulation::new(&database.model, &args.scene, args.dt, args.solver)
        .map_err(|e| Failure(format!("{}: {e}", args.db.display())))?;
    sim.world.settings.sleeping = args.sleep;
    let format = args.format.unwrap_or(match &args.out {
        Some(p) if p.extension().is_some_and(|e| e.eq_ignore_ascii_case("csv")) => Format::Csv,
        _ => Format::Jsonl,
    });
    let sink: Box<dyn Write> = match &args.out {
        Some(path) => Box::new(
            std::fs::File::create(path)
                .map_err(|e| Failure(format!("{}: cannot write: {e}", path.display())))?,
        ),
        None => Box::new(std::io::stdout().lock()),
    };
    let mut out = std::io::BufWriter::new(sink);
    let progress = if args.steps >= 5_000 {
        indicatif::ProgressBar::new(args.steps) // drawn only when stderr is a terminal
    } else {
        indicatif::ProgressBar::hidden()
    };
    let write_error = |e: &dyn std::fmt::Display| Failure(format!("writing the trace: {e}"));
    let mut header_written = false;
    let mut emit = |sim: &Simulation, out: &mut dyn Write| -> Result<(), Failure> {
        let record = Record::of(sim);
        match format {
            Format::Jsonl => {
                writeln!(out, "{}", record.to_json_line()).map_err(|e| write_error(&e))
            }
            Format::Csv => {
                let mut w = csv::WriterBuilder::new()
                    .has_headers(false)
                    .from_writer(out);
                if !header_written {
                    w.write_record(record.csv_header())
                        .map_err(|e| write_error(&e))?;
                    header_written = true;
                }
                w.write_record(record.csv_row())
                    .map_err(|e| write_error(&e))?;
                w.flush().map_err(|e| write_error(&e))
            }
        }
    };
    emit(&sim, &mut out)?;
    for _ in 0..args.steps {
        sim.step();
        let step = sim.step_count();
        if sim.has_non_finite_state() {
            return Err(Failure(format!(
                "scene \"{}\": the state became non-finite at step {step}",
                args.scene
            )));
        }
        if step % args.every == 0 || step == args.steps {
            emit(&sim, &mut out)?;
        }
        progress.inc(1);
    }
    progress.finish_and_clear();
    out.flush().map_err(|e| write_error(&e))?;
    Ok(ExitCode::SUCCESS)
}
