//! Hashes of the crate's sources, shared by build.rs (which bakes them into
//! the binary) and the binary itself (which hashes its checkout at run time
//! to tell whether that checkout is what it was built from). Standalone: it
//! imports nothing of the crate, as build.rs includes this file alone.

use std::path::{Path, PathBuf};

/// FNV-1a hashes over the relative path and bytes of every file under `root`
/// (`src/`), in sorted order: `results` skips src/cli and src/report (the
/// layers above `study` cannot change a computed line: tests/architecture.rs
/// keeps the layers), `all` covers every file. Contents, not modification
/// times: a checkout of the same sources hashes the same.
pub struct SourceHashes {
    /// The sources that compute results (the map cache's key).
    pub results: u64,
    /// Every source file.
    pub all: u64,
}

/// The hashes of the files under `root`.
pub fn source_hashes(root: &Path) -> SourceHashes {
    let mut files = Vec::new();
    collect(root, &mut files);
    files.sort();
    let mut results = Fnv::new();
    let mut all = Fnv::new();
    for f in files {
        let rel = f.strip_prefix(root).unwrap_or(&f);
        let name = rel.to_string_lossy();
        let bytes = std::fs::read(&f).unwrap_or_default();
        let computes = !(rel.starts_with("cli") || rel.starts_with("report"));
        all.eat_file(&name, &bytes);
        if computes {
            results.eat_file(&name, &bytes);
        }
    }
    SourceHashes {
        results: results.0,
        all: all.0,
    }
}

struct Fnv(u64);

impl Fnv {
    fn new() -> Self {
        Fnv(0xcbf2_9ce4_8422_2325)
    }

    fn eat_file(&mut self, name: &str, bytes: &[u8]) {
        self.eat(name.as_bytes());
        self.eat(&[0]);
        self.eat(bytes);
        self.eat(&[0]);
    }

    fn eat(&mut self, bytes: &[u8]) {
        for b in bytes {
            self.0 ^= *b as u64;
            self.0 = self.0.wrapping_mul(0x0100_0000_01b3);
        }
    }
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
