//! The `knotrod` command line.

use crate::equilibrium::solve_scene;
use crate::scene::Scene;
use crate::summary::{Summary, print_equilibrium};
use crate::validation;
use anyhow::{Context, Result};
use clap::{Parser, Subcommand};
use std::io::Write;
use std::path::{Path, PathBuf};

/// knotrod: equilibria and stability of clamped elastic rods.
#[derive(Parser, Debug)]
#[command(version, about)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// Subcommands.
#[derive(Subcommand, Debug)]
pub enum Command {
    /// Solve a scene and print its equilibrium.
    Run {
        /// Scene file (TOML).
        scene: PathBuf,
        /// Write the JSON summary here.
        #[arg(long)]
        json: Option<PathBuf>,
        /// Override the scene's number of segments.
        #[arg(long)]
        segments: Option<usize>,
    },
    /// Regenerate the validation report (docs/validation.md) on stdout.
    Validate {
        /// Folder holding the scenes.
        #[arg(long, default_value = "scenes")]
        scenes: PathBuf,
    },
    /// Convergence study in N of a scene's equilibrium (markdown table).
    Convergence {
        /// Scene file (TOML).
        scene: PathBuf,
        /// Segment counts, comma separated.
        #[arg(long, value_delimiter = ',', default_value = "50,100,200,400,800")]
        segments: Vec<usize>,
    },
}

/// Run the command line.
pub fn main_with(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Run {
            scene,
            json,
            segments,
        } => run(&scene, json, segments),
        Command::Convergence { scene, segments } => convergence(&scene, &segments),
        Command::Validate { scenes } => {
            write!(std::io::stdout().lock(), "{}", validation::report(&scenes)?)?;
            Ok(())
        }
    }
}

fn run(path: &Path, json: Option<PathBuf>, segments: Option<usize>) -> Result<()> {
    let scene = Scene::load(path)?;
    if let Some(n) = segments {
        anyhow::ensure!(
            (4..=1_000_000).contains(&n),
            "--segments must be in 4..=1000000, got {n}"
        );
    }
    let model = scene.rod_model(segments);
    let start = std::time::Instant::now();
    let eq = solve_scene(&scene, segments)?;
    let mut summary = Summary::new(&scene, &model);
    let mut out = std::io::stdout().lock();
    writeln!(
        out,
        "scene {} — Kirchhoff rod, K2 = {}, K3 = {}, N = {} ({:.2} s)",
        summary.scene,
        model.k2,
        model.k3,
        model.segments,
        start.elapsed().as_secs_f64()
    )?;
    print_equilibrium(&eq, &scene, &mut out)?;
    summary.equilibria.push(eq);
    if let Some(path) = json.or(scene.output.json.clone()) {
        summary
            .write(&path)
            .with_context(|| format!("writing {}", path.display()))?;
        writeln!(out, "summary written to {}", path.display())?;
    }
    Ok(())
}

fn convergence(path: &Path, segments: &[usize]) -> Result<()> {
    let scene = Scene::load(path)?;
    write!(
        std::io::stdout().lock(),
        "{}",
        validation::convergence_table(&scene, segments)?
    )?;
    Ok(())
}
