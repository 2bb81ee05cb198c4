//! The crate's architecture, read from its own source: every file of `src/`
//! lives in a layer folder, imports (`crate::` and `super::` paths) go only to
//! the same layer or layers below it in the order docs/design.md lists, and
//! no files import each other in a loop (re-exports are followed to the file
//! that defines the name).

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// The layers, bottom first, from the table under "## Layers" in docs/design.md.
fn layers() -> Vec<String> {
    let design = std::fs::read_to_string(root().join("docs/design.md")).expect("docs/design.md");
    let section = design
        .split("## Layers")
        .nth(1)
        .expect("docs/design.md has a `## Layers` section");
    let layers: Vec<String> = section
        .lines()
        .take_while(|l| !l.starts_with("## "))
        .filter_map(|l| l.trim().strip_prefix("| `"))
        .filter_map(|l| l.split('`').next())
        .map(|s| s.trim_end_matches('/').to_string())
        .collect();
    assert!(layers.len() >= 5, "layer table not found: {layers:?}");
    layers
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// One source file: its module path and the text that counts (comments and
/// the trailing test module removed).
struct File {
    module: Vec<String>,
    code: String,
}

fn source_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let p = entry.unwrap().path();
        if p.is_dir() {
            source_files(&p, out);
        } else if p.extension().is_some_and(|e| e == "rs") {
            out.push(p);
        }
    }
}

fn strip(text: &str) -> String {
    // the unit tests at the end of a file test it from inside: not imports
    let text = text.split("#[cfg(test)]").next().unwrap_or("");
    text.lines()
        .map(|l| match l.find("//") {
            Some(k) => &l[..k],
            None => l,
        })
        .collect::<Vec<_>>()
        .join("\n")
}

fn read_crate() -> BTreeMap<PathBuf, File> {
    let src = root().join("src");
    let mut paths = Vec::new();
    source_files(&src, &mut paths);
    paths
        .into_iter()
        .map(|p| {
            let rel = p.strip_prefix(&src).unwrap().to_path_buf();
            let mut module: Vec<String> = rel
                .with_extension("")
                .iter()
                .map(|c| c.to_string_lossy().into_owned())
                .collect();
            if module.last().is_some_and(|m| m == "mod") {
                module.pop();
            }
            let code = strip(&std::fs::read_to_string(&p).unwrap());
            (rel, File { module, code })
        })
        .collect()
}

/// Paths used by a file, each as module segments (`crate::a::b::C` →
/// [a, b, C]; `super::x` and child modules resolved), with whether it is a
/// `pub use` (a re-export).
fn uses(file: &File) -> Vec<(Vec<String>, bool)> {
    let children: BTreeSet<String> = file
        .code
        .lines()
        .filter_map(|l| {
            let l = l.trim();
            let l = l.strip_prefix("pub ").unwrap_or(l);
            let l = l.strip_prefix("pub(crate) ").unwrap_or(l);
            l.strip_prefix("mod ")?
                .strip_suffix(';')
                .map(str::to_string)
        })
        .collect();
    // bare child paths start in this module, `super::` in its parent
    let here = file.module.clone();
    let parent = {
        let mut p = file.module.clone();
        p.pop();
        p
    };
    let mut out = Vec::new();
    let code = &file.code;
    let bytes = code.as_bytes();
    let mut k = 0;
    while k < code.len() {
        let rest = &code[k..];
        let (base, skip, public) = if rest.starts_with("crate::") && !preceded_by_ident(bytes, k) {
            (Vec::new(), "crate::".len(), is_pub_use(code, k))
        } else if rest.starts_with("super::") && !preceded_by_ident(bytes, k) {
            (parent.clone(), "super::".len(), is_pub_use(code, k))
        } else if let Some(child) = children
            .iter()
            .find(|c| rest.starts_with(&format!("{c}::")) && !preceded_by_ident(bytes, k))
        {
            let mut b = here.clone();
            b.push(child.clone());
            (b, child.len() + 2, is_pub_use(code, k))
        } else {
            k += rest.chars().next().map_or(1, char::len_utf8);
            continue;
        };
        let tail = &code[k + skip..];
        let (paths, used) = parse_tree(tail);
        for p in paths {
            let mut full = base.clone();
            full.extend(p);
            out.push((full, public));
        }
        k += skip + used.max(1);
    }
    out
}

fn preceded_by_ident(bytes: &[u8], k: usize) -> bool {
    k > 0 && (bytes[k - 1].is_ascii_alphanumeric() || bytes[k - 1] == b'_' || bytes[k - 1] == b':')
}

/// Whether the path at byte `k` is part of a `pub use` statement.
fn is_pub_use(code: &str, k: usize) -> bool {
    let start = code[..k].rfind(';').map_or(0, |s| s + 1);
    let stmt = code[start..k].trim_start();
    let stmt = stmt.rsplit('}').next().unwrap_or(stmt).trim_start();
    stmt.starts_with("pub use") || stmt.starts_with("pub(crate) use")
}

/// Parse `a::b::{c, d::e}` at the start of `s` into paths, and the bytes used.
fn parse_tree(s: &str) -> (Vec<Vec<String>>, usize) {
    let ident = |s: &str| -> usize {
        s.char_indices()
            .find(|(_, c)| !(c.is_alphanumeric() || *c == '_'))
            .map_or(s.len(), |(i, _)| i)
    };
    let mut prefix = Vec::new();
    let mut k = 0;
    loop {
        let n = ident(&s[k..]);
        if n == 0 {
            if s[k..].starts_with('{') {
                let (mut group, used) = parse_group(&s[k + 1..]);
                for g in group.iter_mut() {
                    let mut p = prefix.clone();
                    p.append(g);
                    *g = p;
                }
                return (group, k + 1 + used);
            }
            return (vec![prefix], k);
        }
        prefix.push(s[k..k + n].to_string());
        k += n;
        if s[k..].starts_with("::") {
            k += 2;
        } else {
            return (vec![prefix], k);
        }
    }
}

fn parse_group(s: &str) -> (Vec<Vec<String>>, usize) {
    let mut out = Vec::new();
    let mut k = 0;
    loop {
        let t = &s[k..];
        let skip = t.len() - t.trim_start().len();
        k += skip;
        let t = &s[k..];
        if t.starts_with('}') || t.is_empty() {
            return (out, k + 1);
        }
        if t.starts_with(',') {
            k += 1;
            continue;
        }
        let (paths, used) = parse_tree(t);
        out.extend(
            paths
                .into_iter()
                .filter(|p| !p.is_empty() && p[0] != "self"),
        );
        // skip an `as` rename
        k += used.max(1);
        if let Some(end) = s[k..].find([',', '}']) {
            k += end;
        }
    }
}

/// The file that module path `module` is (src/a/b.rs or src/a/b/mod.rs).
fn file_of(files: &BTreeMap<PathBuf, File>, module: &[String]) -> Option<PathBuf> {
    files
        .iter()
        .find(|(_, f)| f.module == module)
        .map(|(p, _)| p.clone())
}

/// The file that defines the name a path leads to: the deepest module that is
/// a file, following its re-exports (`pub use child::Name`).
fn resolve(files: &BTreeMap<PathBuf, File>, path: &[String], depth: usize) -> Option<PathBuf> {
    let (len, file) = (1..=path.len())
        .rev()
        .find_map(|n| file_of(files, &path[..n]).map(|f| (n, f)))?;
    if depth > 8 || len == path.len() {
        return Some(file);
    }
    let name = &path[len];
    for (target, public) in uses(&files[&file]) {
        if public
            && target.last() == Some(name)
            && target.len() > len
            && let Some(f) = resolve(files, &target, depth + 1)
        {
            return Some(f);
        }
    }
    Some(file)
}

fn graph() -> (
    BTreeMap<PathBuf, File>,
    BTreeMap<PathBuf, BTreeSet<PathBuf>>,
) {
    let files = read_crate();
    let mut edges: BTreeMap<PathBuf, BTreeSet<PathBuf>> = BTreeMap::new();
    for (p, f) in &files {
        let out = edges.entry(p.clone()).or_default();
        for (target, _) in uses(f) {
            if let Some(t) = resolve(&files, &target, 0)
                && &t != p
            {
                out.insert(t);
            }
        }
    }
    (files, edges)
}

fn layer_of(p: &Path) -> Option<String> {
    let first = p.iter().next()?.to_string_lossy().into_owned();
    (p.iter().count() > 1).then_some(first)
}

#[test]
fn every_file_lives_in_a_layer_folder() {
    let layers = layers();
    let (files, _) = graph();
    for p in files.keys() {
        match layer_of(p) {
            Some(l) => assert!(
                layers.contains(&l),
                "{} is in `{l}`, not a layer of docs/design.md",
                p.display()
            ),
            None => assert!(
                p == Path::new("lib.rs") || p == Path::new("main.rs"),
                "{} lies loose in src/",
                p.display()
            ),
        }
    }
    for l in &layers {
        assert!(
            root().join("src").join(l).is_dir(),
            "layer `{l}` has no folder"
        );
    }
}

#[test]
fn imports_go_only_down_the_layers() {
    let layers = layers();
    let rank = |l: &str| layers.iter().position(|x| x == l);
    let (_, edges) = graph();
    let mut upward = Vec::new();
    for (from, targets) in &edges {
        let Some(lf) = layer_of(from) else { continue };
        for to in targets {
            let Some(lt) = layer_of(to) else { continue };
            if rank(&lt) > rank(&lf) {
                upward.push(format!(
                    "{} ({lf}) -> {} ({lt})",
                    from.display(),
                    to.display()
                ));
            }
        }
    }
    assert!(
        upward.is_empty(),
        "imports from a layer to one above it:\n{}",
        upward.join("\n")
    );
}

#[test]
fn no_files_import_each_other_in_a_loop() {
    let (_, edges) = graph();
    // Tarjan's strongly connected components
    struct State<'a> {
        edges: &'a BTreeMap<PathBuf, BTreeSet<PathBuf>>,
        index: BTreeMap<&'a PathBuf, usize>,
        low: BTreeMap<&'a PathBuf, usize>,
        stack: Vec<&'a PathBuf>,
        on_stack: BTreeSet<&'a PathBuf>,
        loops: Vec<Vec<&'a PathBuf>>,
    }
    fn visit<'a>(s: &mut State<'a>, v: &'a PathBuf) {
        let k = s.index.len();
        s.index.insert(v, k);
        s.low.insert(v, k);
        s.stack.push(v);
        s.on_stack.insert(v);
        for w in s.edges.get(v).into_iter().flatten() {
            if !s.index.contains_key(w) {
                visit(s, w);
                let lw = s.low[w];
                let lv = s.low.get_mut(v).unwrap();
                *lv = (*lv).min(lw);
            } else if s.on_stack.contains(w) {
                let iw = s.index[w];
                let lv = s.low.get_mut(v).unwrap();
                *lv = (*lv).min(iw);
            }
        }
        if s.low[v] == s.index[v] {
            let mut component = Vec::new();
            while let Some(w) = s.stack.pop() {
                s.on_stack.remove(w);
                component.push(w);
                if w == v {
                    break;
                }
            }
            if component.len() > 1 {
                s.loops.push(component);
            }
        }
    }
    let mut s = State {
        edges: &edges,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        on_stack: BTreeSet::new(),
        loops: Vec::new(),
    };
    for v in edges.keys() {
        if !s.index.contains_key(v) {
            visit(&mut s, v);
        }
    }
    let described: Vec<String> = s
        .loops
        .iter()
        .map(|c| {
            c.iter()
                .map(|p| p.display().to_string())
                .collect::<Vec<_>>()
                .join(" ↔ ")
        })
        .collect();
    assert!(
        described.is_empty(),
        "files importing each other in a loop:\n{}",
        described.join("\n")
    );
}

#[test]
fn the_reader_sees_imports_through_groups_super_and_re_exports() {
    // the parser itself, on the forms the crate uses
    let f = File {
        module: vec!["study".into(), "boundary".into()],
        code: "mod walk;\npub use walk::trace_island;\nuse crate::scene::{MapSpec, Scene};\nuse super::map::Line;\nlet x = crate::linalg::sparse::Ldlt::new();".into(),
    };
    let got: Vec<(Vec<String>, bool)> = uses(&f);
    let s = |v: &[&str]| v.iter().map(|x| x.to_string()).collect::<Vec<_>>();
    assert!(
        got.contains(&(s(&["study", "boundary", "walk", "trace_island"]), true)),
        "{got:?}"
    );
    assert!(got.contains(&(s(&["scene", "MapSpec"]), false)), "{got:?}");
    assert!(got.contains(&(s(&["scene", "Scene"]), false)), "{got:?}");
    assert!(
        got.contains(&(s(&["study", "map", "Line"]), false)),
        "{got:?}"
    );
    assert!(
        got.contains(&(s(&["linalg", "sparse", "Ldlt", "new"]), false)),
        "{got:?}"
    );
}

/// The crate's files outside the layers `exempt` whose code contains any of
/// `marks`.
fn files_outside_with(exempt: &[&str], marks: &[&str]) -> Vec<String> {
    let files = read_crate();
    assert!(files.len() > 50, "the crate's files were read");
    files
        .iter()
        .map(|(path, file)| (path.to_string_lossy().replace('\\', "/"), file))
        .filter(|(p, _)| {
            !exempt
                .iter()
                .any(|l| p.starts_with(&format!("{l}/")) || p.contains(&format!("/{l}/")))
        })
        .filter(|(_, file)| marks.iter().any(|m| file.code.contains(m)))
        .map(|(p, _)| p)
        .collect()
}

/// One predictor-corrector loop: outside `src/solve/` nothing calls the
/// corrector itself (it steps through `Tracer::advance`); that nothing but
/// `StepControl::advance` halves or grows a step, the compiler sees to
/// (`shrink` and `accepted` are private to solve/step.rs).
#[test]
fn only_solve_calls_the_corrector() {
    let offenders = files_outside_with(&["solve"], &[".correct("]);
    assert!(
        offenders.is_empty(),
        "files outside src/solve/ calling the corrector: {offenders:?}"
    );
}

/// One root finder: outside `src/solve/` (and the equations' own scalar
/// roots in `src/model/`), roots along a family are narrowed by
/// `solve::root` (its secant iteration and bisection), not by a loop of
/// one's own halving a bracket.
#[test]
fn roots_are_narrowed_in_solve() {
    let offenders = files_outside_with(&["solve", "model"], &["0.5 * (lo + hi)", "0.5 * (a + b)"]);
    assert!(
        offenders.is_empty(),
        "files outside src/solve/ bisecting by hand: {offenders:?}"
    );
    // the check sees a hand-written bisection where there is one
    assert!(!files_outside_with(&["solve"], &["0.5 * (lo + hi)"]).is_empty());
}

/// The unit-test harness compiles the crate without its CLI (src/lib.rs):
/// a unit test there would never run.
#[test]
fn the_cli_layer_holds_no_unit_tests() {
    let mut files = Vec::new();
    source_files(&root().join("src/cli"), &mut files);
    assert!(!files.is_empty(), "no src/cli");
    for f in files {
        let text = std::fs::read_to_string(&f).unwrap();
        assert!(
            !text.contains("#[cfg(test)]") && !text.contains("#[test]"),
            "{} holds unit tests, which the harness never compiles (src/lib.rs): \
             test it from tests/",
            f.display()
        );
    }
}
