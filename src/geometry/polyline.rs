//! Curves from text: one point per line, "x y z" or "x,y,z".

use nalgebra::Vector3;

/// A curve's text that is not a curve.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CurveError {
    /// A line that is not three finite numbers.
    #[error("line {line}: {reason}")]
    Line {
        /// Line number, from 1.
        line: usize,
        /// What is wrong with it.
        reason: String,
    },
    /// Too few distinct points.
    #[error("a curve needs at least 3 distinct points, found {0}")]
    TooShort(usize),
}

/// Parse points from text. Blank lines and lines starting with '#' are
/// skipped; a first line that is not numeric is taken as a header.
pub fn parse_points(text: &str) -> Result<Vec<Vector3<f64>>, CurveError> {
    let mut points = Vec::new();
    let mut seen_data = false;
    for (k, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let bad = |reason: String| CurveError::Line {
            line: k + 1,
            reason,
        };
        let fields: Vec<&str> = line
            .split(|c: char| c == ',' || c == ';' || c.is_whitespace())
            .filter(|f| !f.is_empty())
            .collect();
        let values: Result<Vec<f64>, _> = fields.iter().map(|f| f.parse::<f64>()).collect();
        match values {
            Ok(v) if v.len() == 3 => {
                if v.iter().any(|x| !x.is_finite()) {
                    return Err(bad("non-finite coordinate".into()));
                }
                points.push(Vector3::new(v[0], v[1], v[2]));
                seen_data = true;
            }
            Ok(v) => return Err(bad(format!("expected 3 coordinates, found {}", v.len()))),
            Err(_) if !seen_data && points.is_empty() => continue, // header
            Err(e) => return Err(bad(e.to_string())),
        }
    }
    // drop repeated consecutive points, which have no direction (compared
    // exactly: the norm of a difference of 1e-300 underflows to 0)
    points.dedup();
    if points.len() < 3 {
        return Err(CurveError::TooShort(points.len()));
    }
    Ok(points)
}
