//! `knotrod render`: pictures of configurations.

use crate::io::render::{Pick, Picture, View, bodies, png, svg};
use anyhow::{Result, bail, ensure};
use std::io::Write;
use std::path::Path;

/// Draw the states `index` of `input` (named `label`, if given) to `out` (PNG or SVG by its extension).
pub fn render(
    input: &Path,
    index: &[String],
    label: &[String],
    view: &str,
    size: Option<&str>,
    strip_width: Option<f64>,
    out: &Path,
) -> Result<()> {
    let view = View::parse(view).map_err(anyhow::Error::msg)?;
    if let Some(w) = strip_width {
        ensure!(
            w.is_finite() && w > 0.0 && w <= 0.5,
            "--strip-width {w}: a width between 0 and half the rod's length"
        );
    }
    let svg_out = match out.extension().and_then(|e| e.to_str()) {
        Some(e) if e.eq_ignore_ascii_case("png") => false,
        Some(e) if e.eq_ignore_ascii_case("svg") => true,
        _ => bail!("--out {}: name a .png or .svg picture", out.display()),
    };
    ensure!(!index.is_empty(), "--index: name at least one state");
    ensure!(
        index.len() <= 12,
        "--index: at most 12 states side by side, got {}",
        index.len()
    );
    let (width, height) = match size {
        Some(s) => Picture::parse_size(s).map_err(anyhow::Error::msg)?,
        None if index.len() == 1 => (1200, 900),
        None => (800 * index.len() as u32, 900),
    };
    let picks = index
        .iter()
        .map(|s| Pick::parse(s))
        .collect::<Result<Vec<Pick>, String>>()
        .map_err(anyhow::Error::msg)?;
    ensure!(
        label.is_empty() || label.len() == index.len(),
        "--label: one name per state ({} names for {} states)",
        label.len(),
        index.len()
    );
    let mut bodies = bodies(input, &picks, strip_width)?;
    for (b, name) in bodies.iter_mut().zip(label) {
        b.label.clone_from(name);
    }
    let picture = Picture {
        width,
        height,
        view,
    };
    let bytes = if svg_out {
        svg(&bodies, &picture).into_bytes()
    } else {
        png(&bodies, &picture)?
    };
    crate::io::output::write_file(out, &bytes)?;
    if !crate::io::output::is_standard_output(out) {
        writeln!(
            std::io::stdout().lock(),
            "picture written to {}",
            out.display()
        )?;
    }
    Ok(())
}
