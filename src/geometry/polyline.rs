//! Reading curves from text: one point per line, "x y z" or "x,y,z".

use anyhow::{Context, Result, bail};
use nalgebra::Vector3;
use std::path::Path;

/// Parse points from text. Blank lines and lines starting with '#' are
/// skipped; a first line that is not numeric is taken as a header.
pub fn parse_points(text: &str) -> Result<Vec<Vector3<f64>>> {
    let mut points = Vec::new();
    let mut seen_data = false;
    for (k, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let fields: Vec<&str> = line
            .split(|c: char| c == ',' || c == ';' || c.is_whitespace())
            .filter(|f| !f.is_empty())
            .collect();
        let values: Result<Vec<f64>, _> = fields.iter().map(|f| f.parse::<f64>()).collect();
        match values {
            Ok(v) if v.len() == 3 => {
                if v.iter().any(|x| !x.is_finite()) {
                    bail!("line {}: non-finite coordinate", k + 1);
                }
                points.push(Vector3::new(v[0], v[1], v[2]));
                seen_data = true;
            }
            Ok(v) => bail!("line {}: expected 3 coordinates, found {}", k + 1, v.len()),
            Err(_) if !seen_data && points.is_empty() => continue, // header
            Err(e) => bail!("line {}: {e}", k + 1),
        }
    }
    // drop repeated consecutive points, which have no direction
    points.dedup_by(|a, b| (*a - *b).norm() == 0.0);
    if points.len() < 3 {
        bail!(
            "a curve needs at least 3 distinct points, found {}",
            points.len()
        );
    }
    Ok(points)
}

/// Read a curve file.
pub fn read_points(path: &Path) -> Result<Vec<Vector3<f64>>> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("cannot read curve {}", path.display()))?;
    parse_points(&text).with_context(|| format!("curve {}", path.display()))
}
