//! The `knotrod` command line.

use crate::equilibrium::{Equilibrium, solve_scene};
use crate::model::shooting::{ShootingSolution, refine_shooting};
use crate::scene::{InitialShape, Scene};
use crate::summary::{Summary, print_equilibrium};
use anyhow::{Context, Result};
use clap::{Parser, Subcommand};
use nalgebra::Vector3;
use std::path::PathBuf;

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
    }
}

fn run(path: &PathBuf, json: Option<PathBuf>, segments: Option<usize>) -> Result<()> {
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
    println!(
        "scene {} — Kirchhoff rod, K2 = {}, K3 = {}, N = {} ({:.2} s)",
        summary.scene,
        model.k2,
        model.k3,
        model.segments,
        start.elapsed().as_secs_f64()
    );
    print_equilibrium(&eq, &scene, &mut std::io::stdout())?;
    summary.equilibria.push(eq);
    if let Some(out) = json.or(scene.output.json.clone()) {
        summary
            .write(&out)
            .with_context(|| format!("writing {}", out.display()))?;
        println!("summary written to {}", out.display());
    }
    Ok(())
}

fn norm3(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y) * (x - y))
        .sum::<f64>()
        .sqrt()
}

fn order(e_coarse: f64, e_fine: f64) -> String {
    if e_coarse > 0.0 && e_fine > 0.0 {
        format!("{:.2}", (e_coarse / e_fine).log2())
    } else {
        "–".into()
    }
}

fn convergence(path: &PathBuf, segments: &[usize]) -> Result<()> {
    let scene = Scene::load(path)?;
    let model = scene.rod_model(None);
    let mut rows: Vec<(usize, Equilibrium, f64)> = Vec::new();
    for &n in segments {
        let t = std::time::Instant::now();
        let eq = solve_scene(&scene, Some(n)).with_context(|| format!("N = {n}"))?;
        rows.push((n, eq, t.elapsed().as_secs_f64()));
    }
    // continuum reference: the shooting data refined on the boundary conditions
    let reference = if scene.initial.shape == InitialShape::Shooting {
        let (n0, m0) = (scene.initial.n0.unwrap(), scene.initial.m0.unwrap());
        refine_shooting(
            Vector3::from(n0),
            Vector3::from(m0),
            model.k2,
            model.k3,
            &scene.clamps(),
            40_000,
        )
        .map(|(n0, m0)| {
            let tw = ShootingSolution::integrate(n0, m0, model.k2, model.k3, 40_000).twist();
            (<[f64; 3]>::from(n0), <[f64; 3]>::from(m0), tw)
        })
    } else {
        None
    };
    println!(
        "Convergence in N for scene {} (K2 = {}, K3 = {}, stretching stiffness {:.3e})\n",
        scene.name.as_deref().unwrap_or(""),
        model.k2,
        model.k3,
        model.stretching_stiffness
    );
    println!(
        "| N | n1(0) | n2(0) | n3(0) | m1(0) | m2(0) | m3(0) | Tw | E | lowest ω² | Newton its | time (s) |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|");
    for (n, e, t) in &rows {
        println!(
            "| {n} | {:.4} | {:.4} | {:.4} | {:.4} | {:.4} | {:.4} | {:.6} | {:.6} | {:.4} | {} | {:.2} |",
            e.n0[0],
            e.n0[1],
            e.n0[2],
            e.m0[0],
            e.m0[1],
            e.m0[2],
            e.twist,
            e.energy,
            e.omega_squared.first().copied().unwrap_or(f64::NAN),
            e.iterations,
            t
        );
    }
    if let Some((n0, m0, tw)) = &reference {
        println!(
            "| shooting (refined) | {:.4} | {:.4} | {:.4} | {:.4} | {:.4} | {:.4} | {:.6} | | | | |",
            n0[0], n0[1], n0[2], m0[0], m0[1], m0[2], tw
        );
        println!(
            "\nErrors against the refined shooting solution and observed order p = log2(e(N)/e(2N)):\n"
        );
        println!("| N | ‖n(0) − n_ref‖ | p | ‖m(0) − m_ref‖ | p | |Tw − Tw_ref| | p |");
        println!("|---|---|---|---|---|---|---|");
        let errs: Vec<(f64, f64, f64)> = rows
            .iter()
            .map(|(_, e, _)| (norm3(&e.n0, n0), norm3(&e.m0, m0), (e.twist - tw).abs()))
            .collect();
        for (k, (n, _, _)) in rows.iter().enumerate() {
            let p = |f: fn(&(f64, f64, f64)) -> f64| {
                if k > 0 {
                    order(f(&errs[k - 1]), f(&errs[k]))
                } else {
                    "".into()
                }
            };
            println!(
                "| {n} | {:.3e} | {} | {:.3e} | {} | {:.3e} | {} |",
                errs[k].0,
                p(|e| e.0),
                errs[k].1,
                p(|e| e.1),
                errs[k].2,
                p(|e| e.2)
            );
        }
    }
    println!(
        "\nSelf-convergence (no continuum reference needed): differences between successive N and order p = log2(d(N)/d(2N)):\n"
    );
    println!("| N → 2N | ‖Δn(0)‖ | p | ‖Δm(0)‖ | p | |ΔTw| | p | |ΔE| | p | |Δω²₁| | p |");
    println!("|---|---|---|---|---|---|---|---|---|---|---|");
    let diffs: Vec<[f64; 5]> = rows
        .windows(2)
        .map(|w| {
            let (a, b) = (&w[0].1, &w[1].1);
            [
                norm3(&a.n0, &b.n0),
                norm3(&a.m0, &b.m0),
                (a.twist - b.twist).abs(),
                (a.energy - b.energy).abs(),
                (a.omega_squared.first().unwrap_or(&f64::NAN)
                    - b.omega_squared.first().unwrap_or(&f64::NAN))
                .abs(),
            ]
        })
        .collect();
    for (k, d) in diffs.iter().enumerate() {
        let mut line = format!("| {} → {} ", rows[k].0, rows[k + 1].0);
        for c in 0..5 {
            let p = if k > 0 {
                order(diffs[k - 1][c], d[c])
            } else {
                String::new()
            };
            line += &format!("| {:.3e} | {} ", d[c], p);
        }
        println!("{line}|");
    }
    Ok(())
}
