//! What built this binary: the hash of the sources that compute results (the
//! map cache's key) and the git revision, read at run time from the checkout
//! it was built in, so that a commit rebuilds nothing (build.rs).

use crate::io::source_hash::source_hashes;
use std::path::Path;
use std::process::Command;
use std::sync::OnceLock;

/// The version of the sources that compute a map's lines: a hash of their
/// contents made by build.rs (not the package version, which a rebuild keeps).
pub const SOURCE_HASH: &str = env!("KNOTROD_SOURCE_HASH");

/// The hash of every source file the binary was built from.
const ALL_SOURCES_HASH: &str = env!("KNOTROD_ALL_SOURCES_HASH");

/// The revision this binary was built from: `KNOTROD_REVISION` if it was set
/// at build time (release packaging), else the checkout's `HEAD` (with
/// `-dirty` where `src/` differs from it) if that checkout's sources are
/// still the ones built, else `unknown`. Asked once per process.
pub fn git_revision() -> &'static str {
    static REVISION: OnceLock<String> = OnceLock::new();
    REVISION.get_or_init(|| match option_env!("KNOTROD_REVISION") {
        Some(r) => r.to_string(),
        None => checkout_revision(Path::new(env!("CARGO_MANIFEST_DIR")))
            .unwrap_or_else(|| "unknown".into()),
    })
}

/// HEAD of the checkout at `dir`, if its sources hash as the binary's.
fn checkout_revision(dir: &Path) -> Option<String> {
    let all = format!("{:016x}", source_hashes(&dir.join("src")).all);
    if all != ALL_SOURCES_HASH {
        return None;
    }
    let git = |args: &[&str]| {
        Command::new("git")
            .arg("-C")
            .arg(dir)
            .args(args)
            .output()
            .ok()
            .filter(|o| o.status.success())
            .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
    };
    let rev = git(&["rev-parse", "--short=12", "HEAD"])?;
    let changed = git(&["status", "--porcelain", "--", "src"])?;
    Some(if changed.is_empty() {
        rev
    } else {
        format!("{rev}-dirty")
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_checkout_built_from_is_recognised() {
        // the tests run in the checkout they were built from
        let here = Path::new(env!("CARGO_MANIFEST_DIR"));
        assert_eq!(
            format!("{:016x}", source_hashes(&here.join("src")).all),
            ALL_SOURCES_HASH
        );
        // a folder with other sources is not that checkout
        assert_eq!(checkout_revision(&here.join("docs")), None);
    }
}
