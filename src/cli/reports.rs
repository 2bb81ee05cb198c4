//! `knotrod bench`, `knotrod validate` and `knotrod convergence`: the reports.

use crate::io::json::write_pretty;
use crate::report::validation;
use crate::scene::{Job, Scene};
use anyhow::Result;
use std::io::Write;
use std::path::{Path, PathBuf};

/// Time the standard workloads; print the report, and write it as JSON.
pub fn bench(scenes: &Path, json: Option<PathBuf>) -> Result<()> {
    let r = crate::report::bench::run(scenes)?;
    crate::report::bench::print(&r, &mut std::io::stdout().lock())?;
    if let Some(p) = json {
        write_pretty(&p, &r)?;
    }
    Ok(())
}

/// Print the validation report.
pub fn validate(scenes: &Path) -> Result<()> {
    write!(std::io::stdout().lock(), "{}", validation::report(scenes)?)?;
    Ok(())
}

/// Print the convergence table in N of a scene's equilibrium.
pub fn convergence(path: &Path, segments: &[usize], allow_large: bool) -> Result<()> {
    let scene = Scene::load(path)?;
    for &n in segments {
        anyhow::ensure!(
            (4..=1_000_000).contains(&n),
            "--segments must be in 4..=1000000, got {n}"
        );
        scene.check_budget(Job::Run, Some(n), allow_large)?;
    }
    write!(
        std::io::stdout().lock(),
        "{}",
        validation::convergence_table(&scene, segments)?
    )?;
    Ok(())
}
