//! `[budget]` and the estimate it is checked against (the estimate itself is
//! `Scene::estimate`, in budget.rs).

use serde::{Deserialize, Serialize};

/// `[budget]`: the largest run the scene may start without `--allow-large`.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BudgetSpec {
    /// Most memory, in GB (10⁹ bytes).
    #[serde(default = "default_memory_gb")]
    pub memory_gb: f64,
    /// Most CPU time, in hours.
    #[serde(default = "default_hours")]
    pub hours: f64,
}

impl Default for BudgetSpec {
    fn default() -> Self {
        BudgetSpec {
            memory_gb: default_memory_gb(),
            hours: default_hours(),
        }
    }
}

fn default_memory_gb() -> f64 {
    2.0
}
fn default_hours() -> f64 {
    1.0
}

/// Which command the work is for: a run follows the scene's branches or
/// loading path, a map one branch per line.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Job {
    /// `knotrod run` (and `convergence`, once per N).
    Run,
    /// `knotrod map`.
    Map,
}

/// The predicted cost of a scene, with what drives it.
#[derive(Clone, Debug)]
pub struct Estimate {
    /// Peak memory, bytes.
    pub memory_bytes: f64,
    /// What the memory is made of (settings and counts).
    pub memory_from: String,
    /// CPU time, seconds.
    pub seconds: f64,
    /// What the work is made of.
    pub work_from: String,
}

/// Seconds as the largest sensible unit.
pub fn human_time(s: f64) -> String {
    if s < 120.0 {
        format!("{s:.0} s")
    } else if s < 7200.0 {
        format!("{:.0} min", s / 60.0)
    } else if s < 2.0 * 86400.0 {
        format!("{:.1} h", s / 3600.0)
    } else {
        format!("{:.0} days", s / 86400.0)
    }
}
