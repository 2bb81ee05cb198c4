// Records the git revision for recordings' metadata (absent outside a
// checkout), and a hash of the sources that compute results, which keys the
// map's cache of lines: a rebuilt binary never resumes lines from another
// build's solver.
use std::path::{Path, PathBuf};

fn main() {
    let rev = std::process::Command::new("git")
        .args(["rev-parse", "--short=12", "HEAD"])
        .output()
        .ok()
        .filter(|o| o.status.success())
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
        .unwrap_or_else(|| "unknown".into());
    println!("cargo:rustc-env=KNOTROD_GIT_REVISION={rev}");
    // only paths that exist: a missing one (.git/HEAD of a worktree, whose
    // .git is a file) reruns this script, and rebuilds the crate, every time
    for p in git_paths() {
        if p.exists() {
            println!("cargo:rerun-if-changed={}", p.display());
        }
    }
    println!(
        "cargo:rustc-env=KNOTROD_SOURCE_HASH={:016x}",
        source_hash(Path::new("src"))
    );
    // a folder is scanned whole: any file added, removed or edited reruns this
    println!("cargo:rerun-if-changed=src");
}

/// HEAD and its branch's head in the checkout: `.git` itself, or the folder a
/// worktree's `.git` file names (whose branch heads are in the common folder).
fn git_paths() -> Vec<PathBuf> {
    let git = PathBuf::from(".git");
    let dir = match std::fs::read_to_string(&git) {
        Ok(t) => match t.trim().strip_prefix("gitdir:") {
            Some(d) => PathBuf::from(d.trim()),
            None => return vec![],
        },
        Err(_) => git,
    };
    let common = std::fs::read_to_string(dir.join("commondir"))
        .map_or_else(|_| dir.clone(), |c| dir.join(c.trim()));
    let mut paths = vec![dir.join("HEAD")];
    // the branch HEAD names (not all of refs/heads: another branch's commit
    // need not rebuild this one)
    if let Some(r) = std::fs::read_to_string(dir.join("HEAD"))
        .ok()
        .and_then(|h| h.trim().strip_prefix("ref:").map(|r| r.trim().to_string()))
    {
        paths.push(common.join(r));
    }
    paths
}

/// FNV-1a over the relative path and bytes of every file under `root`, in
/// sorted order, except src/cli and src/report: the layers above `study`
/// cannot change a computed line (tests/architecture.rs keeps the layers).
/// Contents, not modification times: a checkout of the same sources hashes
/// the same.
fn source_hash(root: &Path) -> u64 {
    let mut files = Vec::new();
    collect(root, &mut files);
    files.sort();
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    let mut eat = |bytes: &[u8]| {
        for b in bytes {
            h ^= *b as u64;
            h = h.wrapping_mul(0x0100_0000_01b3);
        }
    };
    for f in files {
        let rel = f.strip_prefix(root).unwrap_or(&f);
        if rel.starts_with("cli") || rel.starts_with("report") {
            continue;
        }
        eat(rel.to_string_lossy().as_bytes());
        eat(&[0]);
        eat(&std::fs::read(&f).unwrap_or_default());
        eat(&[0]);
    }
    h
}

fn collect(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries.flatten() {
        let p = e.path();
        if p.is_dir() {
            collect(&p, out);
        } else {
            out.push(p);
        }
    }
}
