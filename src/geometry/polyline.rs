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

/// Whether a line's fields name three columns ("x y z", "x,y,z", "X [m]"
/// split into three names): each begins with a letter, an underscore or a
/// quote and none is a number, so a mistyped number ("2.O") is not one.
fn names_columns(fields: &[&str]) -> bool {
    fields.len() == 3
        && fields.iter().all(|f| {
            f.parse::<f64>().is_err()
                && f.chars()
                    .next()
                    .is_some_and(|c| c.is_alphabetic() || c == '_' || c == '"' || c == '\'')
        })
}

/// Parse points from text. Blank lines and lines starting with '#' are
/// skipped; the first other line may be a header naming the three columns
/// ([`names_columns`]); any other line that is not three numbers is an error
/// with its number.
pub fn parse_points(text: &str) -> Result<Vec<Vector3<f64>>, CurveError> {
    let mut points = Vec::new();
    let mut first = true;
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
        let header = std::mem::replace(&mut first, false) && names_columns(&fields);
        if header {
            continue;
        }
        let values: Result<Vec<f64>, _> = fields.iter().map(|f| f.parse::<f64>()).collect();
        match values {
            Ok(v) if v.len() == 3 => {
                if v.iter().any(|x| !x.is_finite()) {
                    return Err(bad("non-finite coordinate".into()));
                }
                points.push(Vector3::new(v[0], v[1], v[2]));
            }
            Ok(v) => return Err(bad(format!("expected 3 coordinates, found {}", v.len()))),
            Err(e) => {
                return Err(bad(format!(
                    "{e}: not three numbers{}",
                    if points.is_empty() {
                        " (a header must name three columns, like \"x y z\")"
                    } else {
                        ""
                    }
                )));
            }
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
