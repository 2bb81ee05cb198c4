//! AUTO-07p's own output files, read for `knotrod verify`: the solutions
//! file `s.NAME` (`fort.8`) and the branch file `b.NAME` (`fort.7`), with a
//! small mapping of which AUTO unknowns are n(0) and m(0) and which PAR is
//! which scene parameter. Every labelled solution becomes a verify row; the
//! branch's folds (LP) and branch points (BP) become labelled events to set
//! beside knotrod's own.
//!
//! The solutions file, per labelled point (AUTO-07p's `parseS.py`): a header
//! of 12 integers IBR NTOT ITP LAB NFPR ISW NTPL NAR NROWPR NTST NCOL NPAR
//! (0.9 adds NPARI NDIM IPS IPRIV), then NROWPR lines holding NTPL rows of
//! t and the NAR − 1 unknowns, optionally the NFPR active parameter indices,
//! the NFPR parameter derivatives along the branch and NTPL rows of the
//! unknowns' derivatives (the direction vector), and the NPAR values of PAR.
//! The branch file: lines starting with 0 are its header (the constants, and
//! the column names), the others BR PT TY LAB then the continuation
//! parameter, the norm and the user's output columns.

use crate::model::rod::{Law, Parameter};
use crate::scene::{Scene, SceneError};
use crate::study::verify::{Claims, FoldClaim, Solution};
use std::path::{Path, PathBuf};

/// Most mesh points (NTPL) of one solution read.
pub const MAX_POINTS: usize = 1_000_000;
/// Most unknowns (NDIM) read.
pub const MAX_DIM: usize = 10_000;
/// Most parameters (NPAR) read.
pub const MAX_PAR: usize = 10_000;

pub use crate::io::verify_file::SUPPORTED_FORMATS;

/// Why AUTO-07p files or their mapping could not be used.
#[derive(Debug, thiserror::Error)]
pub enum AutoError {
    /// Reading failed.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// A line of an AUTO file is not what AUTO writes.
    #[error("{path}: line {line}: {field}: {reason}")]
    Format {
        /// The file.
        path: PathBuf,
        /// Line (from 1).
        line: usize,
        /// The field (NTPL, PAR(3), a column, ...).
        field: String,
        /// Why.
        reason: String,
    },
    /// The mapping is missing a field or has a bad one.
    #[error("{source_name}: {field}: {reason}")]
    Map {
        /// The file holding the mapping, or "--map".
        source_name: String,
        /// The field.
        field: String,
        /// Why.
        reason: String,
    },
    /// The base scene could not be read.
    #[error(transparent)]
    Scene(#[from] SceneError),
}

/// What kind of point AUTO says it is (its ITP or TY code, read mod 10).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum PointType {
    /// Not a special point (0).
    Plain,
    /// Branch point: BP (1 algebraic, 6 boundary value problem).
    BranchPoint,
    /// Fold, limit point: LP (2 algebraic, 5 boundary value problem).
    Fold,
    /// Hopf bifurcation: HB (3).
    Hopf,
    /// Regular labelled point, every NPR steps: RG (4).
    Regular,
    /// A user zero, UZSTOP or UZR: UZ (−4).
    UserZero,
    /// Period doubling: PD (7).
    PeriodDoubling,
    /// Torus bifurcation: TR (8).
    Torus,
    /// End point of the branch: EP (9).
    EndPoint,
    /// No convergence: MX (−9).
    NoConvergence,
    /// Another code.
    Other(i64),
}

impl PointType {
    /// From AUTO's ITP / TY code (the tens digit is the branch's type).
    pub fn from_code(code: i64) -> PointType {
        let c = if code < 0 { -((-code) % 10) } else { code % 10 };
        match c {
            0 => PointType::Plain,
            1 | 6 => PointType::BranchPoint,
            2 | 5 => PointType::Fold,
            3 => PointType::Hopf,
            4 => PointType::Regular,
            -4 => PointType::UserZero,
            7 => PointType::PeriodDoubling,
            8 => PointType::Torus,
            9 => PointType::EndPoint,
            -9 => PointType::NoConvergence,
            _ => PointType::Other(code),
        }
    }

    /// AUTO's two-letter name.
    pub fn name(self) -> &'static str {
        match self {
            PointType::Plain => "--",
            PointType::BranchPoint => "BP",
            PointType::Fold => "LP",
            PointType::Hopf => "HB",
            PointType::Regular => "RG",
            PointType::UserZero => "UZ",
            PointType::PeriodDoubling => "PD",
            PointType::Torus => "TR",
            PointType::EndPoint => "EP",
            PointType::NoConvergence => "MX",
            PointType::Other(_) => "??",
        }
    }
}

/// One labelled solution of an `s.NAME` file.
#[derive(Clone, Debug, PartialEq)]
pub struct AutoSolution {
    /// Line of its header (from 1).
    pub line: usize,
    /// IBR, the branch number.
    pub branch: i64,
    /// NTOT, the point's number along the branch.
    pub point: i64,
    /// ITP as read.
    pub code: i64,
    /// What kind of point.
    pub kind: PointType,
    /// LAB.
    pub label: i64,
    /// ISW.
    pub isw: i64,
    /// NTST.
    pub ntst: usize,
    /// NCOL.
    pub ncol: usize,
    /// NDIM (NAR − 1).
    pub ndim: usize,
    /// t at the NTPL mesh points.
    pub t: Vec<f64>,
    /// U(1..NDIM) at each mesh point, row by row (`ndim` values a row).
    pub u: Vec<f64>,
    /// Half a unit in the last printed digit of each U at the first mesh point.
    pub u0_half_units: Vec<f64>,
    /// The active parameters' indices (ICP), when the direction is stored.
    pub active: Vec<i64>,
    /// The active parameters' derivatives along the branch (RLDOT).
    pub parameter_direction: Vec<f64>,
    /// PAR(1..NPAR).
    pub par: Vec<f64>,
    /// Half a unit in the last printed digit of each PAR.
    pub par_half_units: Vec<f64>,
}

impl AutoSolution {
    /// U(1..NDIM) at mesh point `k`.
    pub fn row(&self, k: usize) -> &[f64] {
        &self.u[k * self.ndim..(k + 1) * self.ndim]
    }
}

/// One computed point of a `b.NAME` file.
#[derive(Clone, Debug, PartialEq)]
pub struct BranchRow {
    /// Line (from 1).
    pub line: usize,
    /// BR.
    pub branch: i64,
    /// PT (negative: unstable, for ODEs).
    pub point: i64,
    /// TY as read.
    pub code: i64,
    /// What kind of point.
    pub kind: PointType,
    /// LAB (0: not labelled).
    pub label: i64,
    /// The continuation parameter, the norm and the user's output columns.
    pub values: Vec<f64>,
    /// Half a unit in the last printed digit of each value.
    pub half_units: Vec<f64>,
}

/// An `b.NAME` file: its constants, column names and points.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct AutoBranch {
    /// Names of the value columns (from the last header before the points).
    pub columns: Vec<String>,
    /// EPSS, the relative arclength tolerance of special points, if written.
    pub epss: Option<f64>,
    /// EPSU.
    pub epsu: Option<f64>,
    /// DS, the first step.
    pub ds: Option<f64>,
    /// DSMAX.
    pub dsmax: Option<f64>,
    /// The points.
    pub rows: Vec<BranchRow>,
}

/// A Fortran number as AUTO writes it ("1.5E-003", "1.5D-03", "1.5-100") and
/// half a unit in its last digit.
fn fortran_number(token: &str) -> Option<(f64, f64)> {
    let mut t = token.replace(['D', 'd'], "E");
    if !t.contains(['E', 'e']) {
        // a three-digit exponent drops the E: "1.7976+308"
        if let Some(k) = t[1..].rfind(['+', '-']).map(|k| k + 1)
            && t.as_bytes()[k - 1].is_ascii_digit()
        {
            t.insert(k, 'E');
        }
    }
    let v: f64 = t.parse().ok()?;
    v.is_finite()
        .then(|| (v, crate::io::verify_file::half_unit(&t)))
}

fn read(path: &Path) -> Result<String, AutoError> {
    crate::io::read_text(path, crate::io::DATA_FILE_LIMIT).map_err(|source| AutoError::Io {
        path: path.into(),
        source,
    })
}

/// Every labelled solution of an AUTO-07p solutions file (`s.NAME`, `fort.8`).
pub fn read_solutions_file(path: &Path) -> Result<Vec<AutoSolution>, AutoError> {
    parse_solutions(path, &read(path)?)
}

/// The solutions of `text` (the file `path`, for messages).
pub fn parse_solutions(path: &Path, text: &str) -> Result<Vec<AutoSolution>, AutoError> {
    let lines: Vec<&str> = text.lines().collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < lines.len() {
        if lines[i].trim().is_empty() {
            i += 1;
            continue;
        }
        let (solution, next) = solution_at(path, &lines, i)?;
        out.push(solution);
        if out.len() > crate::io::verify_file::MAX_SOLUTIONS {
            return Err(AutoError::Format {
                path: path.into(),
                line: i + 1,
                field: "LAB".into(),
                reason: format!(
                    "more than {} solutions; the most read is that",
                    crate::io::verify_file::MAX_SOLUTIONS
                ),
            });
        }
        i = next;
    }
    Ok(out)
}

/// A solution's header: its 12 (or 16) integers and the sizes checked
/// against the most a file may hold.
struct Header {
    values: Vec<i64>,
    ntpl: usize,
    nar: usize,
    npar: usize,
    nfpr: usize,
    nrowpr: usize,
    ntst: usize,
    ncol: usize,
}

impl Header {
    /// The header on line `line` (1-based) of `lines`.
    fn read(
        lines: &[&str],
        line: usize,
        bad: &dyn Fn(usize, &str, String) -> AutoError,
    ) -> Result<Header, AutoError> {
        let header: Vec<i64> = lines[line - 1]
            .split_whitespace()
            .map(|w| w.parse::<i64>())
            .collect::<Result<_, _>>()
            .map_err(|_| {
                bad(
                    line,
                    "header",
                    "not a solution's header: 12 (or 16) integers IBR NTOT ITP LAB NFPR ISW \
                     NTPL NAR NROWPR NTST NCOL NPAR"
                        .into(),
                )
            })?;
        if header.len() != 12 && header.len() != 16 {
            return Err(bad(
                line,
                "header",
                format!(
                    "{} integers; a solution's header has 12 (or 16): IBR NTOT ITP LAB NFPR ISW \
                     NTPL NAR NROWPR NTST NCOL NPAR",
                    header.len()
                ),
            ));
        }
        let sized = |k: usize, name: &str, lo: i64, hi: usize| -> Result<usize, AutoError> {
            let v = header[k];
            if v < lo || v > hi as i64 {
                return Err(bad(
                    line,
                    name,
                    format!("{v}; expected {lo} to {hi} (header field {})", k + 1),
                ));
            }
            Ok(v as usize)
        };
        let npar = sized(11, "NPAR", 1, MAX_PAR)?;
        Ok(Header {
            ntpl: sized(6, "NTPL", 1, MAX_POINTS)?,
            nar: sized(7, "NAR", 2, MAX_DIM + 1)?,
            npar,
            nfpr: sized(4, "NFPR", 0, npar)?,
            nrowpr: sized(8, "NROWPR", 1, lines.len() - line)?,
            ntst: sized(9, "NTST", 0, MAX_POINTS)?,
            ncol: sized(10, "NCOL", 0, MAX_POINTS)?,
            values: header,
        })
    }
}

/// The solution whose header is line `i` (0-based) of `lines` (the file
/// `path`), and the index of the line after its block.
fn solution_at(path: &Path, lines: &[&str], i: usize) -> Result<(AutoSolution, usize), AutoError> {
    let bad = |line: usize, field: &str, reason: String| AutoError::Format {
        path: path.into(),
        line,
        field: field.into(),
        reason,
    };
    let line = i + 1;
    let Header {
        values: header,
        ntpl,
        nar,
        npar,
        nfpr,
        nrowpr,
        ntst,
        ncol,
    } = Header::read(lines, line, &bad)?;
    let ndim = nar - 1;
    // the block's numbers, each with its line
    let mut tokens: Vec<(usize, &str)> = Vec::new();
    for (k, l) in lines[line..line + nrowpr].iter().enumerate() {
        tokens.extend(l.split_whitespace().map(|w| (line + 1 + k, w)));
    }
    let small = ntpl * nar + npar;
    let full = small + 2 * nfpr + ndim * ntpl;
    let direction = if tokens.len() == full && full != small {
        true
    } else if tokens.len() == small {
        false
    } else {
        return Err(bad(
            line,
            "NROWPR",
            format!(
                "its {nrowpr} lines hold {} numbers; NTPL × NAR + NPAR = {small} (or {full} \
                     with the direction vector)",
                tokens.len()
            ),
        ));
    };
    let number = |k: usize, what: &dyn Fn() -> String| -> Result<(f64, f64), AutoError> {
        let (l, w) = tokens[k];
        fortran_number(w).ok_or_else(|| bad(l, &what(), format!("`{w}` is not a finite number")))
    };
    let mut t = Vec::with_capacity(ntpl);
    let mut u = Vec::with_capacity(ntpl * ndim);
    let mut u0_half_units = Vec::with_capacity(ndim);
    for p in 0..ntpl {
        t.push(number(p * nar, &|| format!("t of mesh point {}", p + 1))?.0);
        for c in 0..ndim {
            let (v, h) = number(p * nar + 1 + c, &|| {
                format!("U({}) of mesh point {}", c + 1, p + 1)
            })?;
            u.push(v);
            if p == 0 {
                u0_half_units.push(h);
            }
        }
    }
    let mut j = ntpl * nar;
    let (mut active, mut parameter_direction) = (Vec::new(), Vec::new());
    if direction {
        for k in 0..nfpr {
            let (l, w) = tokens[j + k];
            active.push(w.parse::<i64>().map_err(|_| {
                bad(
                    l,
                    &format!("ICP({})", k + 1),
                    format!("`{w}` is not an integer"),
                )
            })?);
        }
        j += nfpr;
        for k in 0..nfpr {
            parameter_direction.push(number(j + k, &|| format!("RLDOT({})", k + 1))?.0);
        }
        // the unknowns' direction is read for its numbers' sake only
        j += nfpr;
        for k in 0..ndim * ntpl {
            number(j + k, &|| format!("UDOT({})", k % ndim + 1))?;
        }
        j += ndim * ntpl;
    }
    let mut par = Vec::with_capacity(npar);
    let mut par_half_units = Vec::with_capacity(npar);
    for k in 0..npar {
        let (v, h) = number(j + k, &|| format!("PAR({})", k + 1))?;
        par.push(v);
        par_half_units.push(h);
    }
    let solution = AutoSolution {
        line,
        branch: header[0],
        point: header[1],
        code: header[2],
        kind: PointType::from_code(header[2]),
        label: header[3],
        isw: header[5],
        ntst,
        ncol,
        ndim,
        t,
        u,
        u0_half_units,
        active,
        parameter_direction,
        par,
        par_half_units,
    };
    Ok((solution, line + nrowpr))
}

/// An AUTO-07p branch file (`b.NAME`, `fort.7`).
pub fn read_branch_file(path: &Path) -> Result<AutoBranch, AutoError> {
    parse_branch(path, &read(path)?)
}

/// The value after `name` (and an `=`) in a header line of constants.
fn constant(line: &str, name: &str) -> Option<f64> {
    let mut words = line
        .split(|c: char| c.is_whitespace() || c == '=')
        .filter(|w| !w.is_empty());
    while let Some(w) = words.next() {
        if w == name {
            return fortran_number(words.next()?).map(|v| v.0);
        }
    }
    None
}

/// The branch of `text` (the file `path`, for messages).
pub fn parse_branch(path: &Path, text: &str) -> Result<AutoBranch, AutoError> {
    let bad = |line: usize, field: &str, reason: String| AutoError::Format {
        path: path.into(),
        line,
        field: field.into(),
        reason,
    };
    let mut b = AutoBranch::default();
    // value columns of the segment being read (a new header starts another)
    let mut width: Option<usize> = None;
    for (k, l) in text.lines().enumerate() {
        let line = k + 1;
        let words: Vec<&str> = l.split_whitespace().collect();
        let Some(first) = words.first() else { continue };
        let br: i64 = first.parse().map_err(|_| {
            bad(
                line,
                "BR",
                format!("`{first}`: a branch file's lines start with an integer BR"),
            )
        })?;
        if br == 0 {
            for (name, slot) in [
                ("EPSS", &mut b.epss),
                ("EPSU", &mut b.epsu),
                ("DS", &mut b.ds),
                ("DSMAX", &mut b.dsmax),
            ] {
                if let Some(v) = constant(l, name) {
                    *slot = Some(v);
                }
            }
            if words.get(1..4) == Some(&["PT", "TY", "LAB"][..]) {
                // names sit in 19-character columns after BR PT TY LAB
                let chars: Vec<char> = l.chars().collect();
                b.columns = chars
                    .get(19..)
                    .unwrap_or(&[])
                    .chunks(19)
                    .map(|c| c.iter().collect::<String>().trim().to_string())
                    .filter(|n| !n.is_empty())
                    .collect();
                width = None;
            }
            continue;
        }
        if words.len() < 5 {
            return Err(bad(
                line,
                "columns",
                format!(
                    "{} numbers; a point has BR PT TY LAB and its values",
                    words.len()
                ),
            ));
        }
        let int = |k: usize, name: &str| -> Result<i64, AutoError> {
            words[k]
                .parse()
                .map_err(|_| bad(line, name, format!("`{}` is not an integer", words[k])))
        };
        let (point, code, label) = (int(1, "PT")?, int(2, "TY")?, int(3, "LAB")?);
        let mut values = Vec::with_capacity(words.len() - 4);
        let mut half_units = Vec::with_capacity(words.len() - 4);
        for (c, w) in words[4..].iter().enumerate() {
            let name = b
                .columns
                .get(c)
                .cloned()
                .unwrap_or_else(|| format!("column {}", c + 5));
            let (v, h) = fortran_number(w)
                .ok_or_else(|| bad(line, &name, format!("`{w}` is not a finite number")))?;
            values.push(v);
            half_units.push(h);
        }
        match width {
            Some(w) if w != values.len() => {
                return Err(bad(
                    line,
                    "columns",
                    format!("{} values; the points above have {w}", values.len()),
                ));
            }
            _ => width = Some(values.len()),
        }
        b.rows.push(BranchRow {
            line,
            branch: br,
            point,
            code,
            kind: PointType::from_code(code),
            label,
            values,
            half_units,
        });
    }
    Ok(b)
}

/// How a knotrod parameter is read from AUTO's PAR.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ParameterMap {
    /// The scene parameter.
    pub parameter: Parameter,
    /// Its PAR index (from 1, as in AUTO).
    pub par: usize,
    /// PAR(par) × factor is the scene's value (φ/2π for φ: 1/2π when AUTO's
    /// is in radians, 1 in turns).
    pub factor: f64,
}

/// Which AUTO unknowns and parameters are knotrod's, and where the files are.
#[derive(Clone, Debug, PartialEq)]
pub struct AutoMap {
    /// The solutions file.
    pub solutions: PathBuf,
    /// The branch file (None: none beside the solutions).
    pub branch: Option<PathBuf>,
    /// U indices (from 1) of the six shooting unknowns at t = 0: n(0), m(0)
    /// for a rod; n(0), u1(0), m2(0), u3(0) for a strip (material frame).
    pub unknowns: [Option<usize>; 6],
    /// The parameters.
    pub parameters: Vec<ParameterMap>,
    /// The base scene.
    pub scene: Option<PathBuf>,
    /// The scene whose continuation locates knotrod's events on the branch.
    pub continuation: Option<PathBuf>,
}

/// A mapping field's value, from TOML or `--map KEY=VALUE`.
enum MapValue {
    Integers(Vec<i64>),
    Text(String),
    Par { par: i64, unit: Option<String> },
}

const MAP_KEYS: &str = "solutions, branch, scene, continuation, n0, m0 (or u1_0, m2_0, u3_0 \
     for a strip) and parameters (scene parameter = { par = k, unit = \"radians\" | \"turns\" \
     for phi })";

impl AutoMap {
    /// The mapping from `fields`; paths are relative to `dir`. `source_name`
    /// names the mapping in messages.
    fn from_fields(
        source_name: &str,
        dir: &Path,
        fields: Vec<(String, MapValue)>,
    ) -> Result<AutoMap, AutoError> {
        let bad = |field: &str, reason: String| AutoError::Map {
            source_name: source_name.into(),
            field: field.into(),
            reason,
        };
        let mut map = AutoMap {
            solutions: PathBuf::new(),
            branch: None,
            unknowns: [None; 6],
            parameters: Vec::new(),
            scene: None,
            continuation: None,
        };
        let mut solutions = None;
        let index = |field: &str, v: i64| -> Result<usize, AutoError> {
            if v < 1 || v as usize > MAX_DIM {
                return Err(bad(
                    field,
                    format!("{v}: AUTO's indices count from 1 (U(1), PAR(1))"),
                ));
            }
            Ok(v as usize)
        };
        for (key, value) in fields {
            let k = key.as_str();
            let path_of = |v: &MapValue| match v {
                MapValue::Text(t) => Ok(dir.join(t)),
                _ => Err(bad(k, "a path (a string)".into())),
            };
            let once = |given: bool| {
                if given {
                    Err(bad(k, "given twice".into()))
                } else {
                    Ok(())
                }
            };
            match k {
                "solutions" => {
                    once(solutions.is_some())?;
                    solutions = Some(path_of(&value)?)
                }
                "branch" => {
                    once(map.branch.is_some())?;
                    map.branch = Some(path_of(&value)?)
                }
                "scene" => {
                    once(map.scene.is_some())?;
                    map.scene = Some(path_of(&value)?)
                }
                "continuation" => {
                    once(map.continuation.is_some())?;
                    map.continuation = Some(path_of(&value)?)
                }
                "n0" | "m0" => {
                    let base = if k == "n0" { 0 } else { 3 };
                    let MapValue::Integers(v) = &value else {
                        return Err(bad(k, "three U indices [i, j, k]".into()));
                    };
                    if v.len() != 3 {
                        return Err(bad(k, format!("{} indices; give three [i, j, k]", v.len())));
                    }
                    once(map.unknowns[base].is_some())?;
                    for (c, &u) in v.iter().enumerate() {
                        map.unknowns[base + c] = Some(index(k, u)?);
                    }
                }
                "u1_0" | "m2_0" | "u3_0" => {
                    let slot = match k {
                        "u1_0" => 3,
                        "m2_0" => 4,
                        _ => 5,
                    };
                    let MapValue::Integers(v) = &value else {
                        return Err(bad(k, "one U index".into()));
                    };
                    let [i] = v[..] else {
                        return Err(bad(k, "one U index".into()));
                    };
                    once(map.unknowns[slot].is_some())?;
                    map.unknowns[slot] = Some(index(k, i)?);
                }
                _ => {
                    let MapValue::Par { par, unit } = value else {
                        return Err(bad(k, format!("unknown field (expected {MAP_KEYS})")));
                    };
                    let (parameter, factor) = match (k, unit.as_deref()) {
                        ("phi", Some("radians")) => (Parameter::Phi, 1.0 / std::f64::consts::TAU),
                        ("phi", Some("turns")) | ("phi_over_2pi", None | Some("turns")) => {
                            (Parameter::Phi, 1.0)
                        }
                        ("phi", None) => {
                            return Err(bad(
                                k,
                                "say the unit of AUTO's φ: unit = \"radians\" or \"turns\" (φ/2π)"
                                    .into(),
                            ));
                        }
                        ("phi" | "phi_over_2pi", Some(u)) => {
                            return Err(bad(k, format!("unit `{u}`: \"radians\" or \"turns\"")));
                        }
                        (_, unit) => {
                            let p = Parameter::named(k).ok_or_else(|| {
                                bad(k, format!("unknown field (expected {MAP_KEYS})"))
                            })?;
                            if let Some(u) = unit {
                                return Err(bad(k, format!("unit `{u}`: only phi takes a unit")));
                            }
                            (p, 1.0)
                        }
                    };
                    if map.parameters.iter().any(|m| m.parameter == parameter) {
                        return Err(bad(k, format!("{} is mapped twice", parameter.name())));
                    }
                    map.parameters.push(ParameterMap {
                        parameter,
                        par: index(k, par)?,
                        factor,
                    });
                }
            }
        }
        map.solutions = solutions.ok_or_else(|| bad("solutions", "missing".into()))?;
        if map.branch.is_none() {
            // AUTO writes the pair side by side: s.NAME with b.NAME, fort.8 with fort.7
            let name = map
                .solutions
                .file_name()
                .and_then(|n| n.to_str())
                .unwrap_or("");
            let beside = match name.strip_prefix("s.") {
                Some(rest) => Some(format!("b.{rest}")),
                None => (name == "fort.8").then(|| "fort.7".to_string()),
            };
            map.branch = beside
                .map(|b| map.solutions.with_file_name(b))
                .filter(|p| p.exists());
        }
        Ok(map)
    }

    /// The mapping in `[auto]` of a TOML verify file (`scene` may also sit
    /// at its top level).
    pub fn from_toml(path: &Path, text: &str) -> Result<AutoMap, AutoError> {
        let source_name = path.display().to_string();
        let bad = |field: &str, reason: String| AutoError::Map {
            source_name: source_name.clone(),
            field: field.into(),
            reason,
        };
        let table: toml::Table = text
            .parse()
            .map_err(|e: toml::de::Error| bad("TOML", e.to_string()))?;
        let mut fields = Vec::new();
        for (key, value) in &table {
            match (key.as_str(), value) {
                ("scene", toml::Value::String(s)) => {
                    fields.push(("scene".into(), MapValue::Text(s.clone())))
                }
                ("scene", _) => return Err(bad("scene", "a path (a string)".into())),
                ("auto", toml::Value::Table(t)) => {
                    for (k, v) in t {
                        fields.extend(toml_fields(&source_name, k, v)?);
                    }
                }
                ("auto", _) => return Err(bad("auto", "a table [auto]".into())),
                (other, _) => {
                    return Err(bad(
                        other,
                        "unknown key (a file of AUTO-07p results has scene and [auto]; rows of \
                         [[solution]] go in a file of their own)"
                            .into(),
                    ));
                }
            }
        }
        let dir = path.parent().unwrap_or(Path::new("."));
        AutoMap::from_fields(&source_name, dir, fields)
    }

    /// The mapping from `--map KEY=VALUE` arguments for the AUTO solutions
    /// file `solutions`: `n0=13,14,15`, `m0=16,17,18`, `phi=1:radians`,
    /// `z_star=2`, `branch=b.NAME`, `continuation=scene.toml`.
    pub fn from_arguments(solutions: &Path, pairs: &[String]) -> Result<AutoMap, AutoError> {
        let bad = |field: &str, reason: String| AutoError::Map {
            source_name: "--map".into(),
            field: field.into(),
            reason,
        };
        let mut fields = vec![(
            "solutions".to_string(),
            MapValue::Text(solutions.display().to_string()),
        )];
        for pair in pairs {
            let (k, v) = pair
                .split_once('=')
                .ok_or_else(|| bad(pair, "KEY=VALUE (e.g. n0=13,14,15 or phi=1:radians)".into()))?;
            let ints = |v: &str| -> Result<Vec<i64>, AutoError> {
                v.split(',')
                    .map(|w| w.trim().parse::<i64>())
                    .collect::<Result<_, _>>()
                    .map_err(|_| bad(k, format!("`{v}`: U indices i,j,k")))
            };
            let value = match k {
                "solutions" | "branch" | "scene" | "continuation" => MapValue::Text(v.into()),
                "n0" | "m0" | "u1_0" | "m2_0" | "u3_0" => MapValue::Integers(ints(v)?),
                _ => {
                    let (par, unit) = match v.split_once(':') {
                        Some((p, u)) => (p, Some(u.trim().to_string())),
                        None => (v, None),
                    };
                    let par = par
                        .trim()
                        .trim_start_matches("PAR")
                        .parse::<i64>()
                        .map_err(|_| bad(k, format!("`{v}`: a PAR index, e.g. 1 or 1:radians")))?;
                    MapValue::Par { par, unit }
                }
            };
            fields.push((k.to_string(), value));
        }
        // the solutions path is the command line's, as given
        AutoMap::from_fields("--map", Path::new(""), fields)
    }
}

fn toml_fields(
    source_name: &str,
    key: &str,
    value: &toml::Value,
) -> Result<Vec<(String, MapValue)>, AutoError> {
    let bad = |field: &str, reason: String| AutoError::Map {
        source_name: source_name.into(),
        field: field.into(),
        reason,
    };
    Ok(match (key, value) {
        ("parameters", toml::Value::Table(t)) => {
            let mut out = Vec::new();
            for (name, spec) in t {
                let field = format!("parameters.{name}");
                let entry = match spec {
                    toml::Value::Integer(par) => MapValue::Par {
                        par: *par,
                        unit: None,
                    },
                    toml::Value::Table(s) => {
                        let mut par = None;
                        let mut unit = None;
                        for (k, v) in s {
                            match (k.as_str(), v) {
                                ("par", toml::Value::Integer(i)) => par = Some(*i),
                                ("unit", toml::Value::String(u)) => unit = Some(u.clone()),
                                _ => {
                                    return Err(bad(
                                        &format!("{field}.{k}"),
                                        "expected par = index (an integer) and, for phi, \
                                         unit = \"radians\" or \"turns\""
                                            .into(),
                                    ));
                                }
                            }
                        }
                        MapValue::Par {
                            par: par.ok_or_else(|| bad(&field, "par = index: missing".into()))?,
                            unit,
                        }
                    }
                    _ => return Err(bad(&field, "{ par = index, unit = … }".into())),
                };
                out.push((name.clone(), entry));
            }
            out
        }
        ("parameters", _) => return Err(bad(key, "a table { name = { par = k } }".into())),
        (_, toml::Value::String(s)) => vec![(key.into(), MapValue::Text(s.clone()))],
        (_, toml::Value::Integer(i)) => vec![(key.into(), MapValue::Integers(vec![*i]))],
        (_, toml::Value::Array(a)) => {
            let v = a
                .iter()
                .map(|x| x.as_integer())
                .collect::<Option<Vec<_>>>()
                .ok_or_else(|| bad(key, "a list of integer U indices".into()))?;
            vec![(key.into(), MapValue::Integers(v))]
        }
        _ => {
            return Err(bad(
                key,
                format!("unknown field or bad value (expected {MAP_KEYS})"),
            ));
        }
    })
}

/// A fold or branch point AUTO located and labelled on its branch.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct AutoEvent {
    /// LP or BP.
    pub kind: PointType,
    /// AUTO's label.
    pub label: i64,
    /// The verify row of its solution, if the solutions file holds it.
    pub row: Option<usize>,
    /// The continuation parameter (a knotrod one), None if unmapped.
    pub parameter: Option<Parameter>,
    /// Its value there (φ as φ/2π).
    pub value: f64,
    /// How far AUTO's own location may be off in the parameter: the
    /// arclength tolerance of its special points, EPSS (1 + √|DS DSMAX|),
    /// times the parameter's derivative along the branch there (None when
    /// the files do not say).
    pub tolerance: Option<f64>,
}

/// AUTO-07p results read for `knotrod verify`.
#[derive(Clone, Debug)]
pub struct AutoInput {
    /// The mapping used.
    pub map: AutoMap,
    /// The base scene.
    pub scene: Scene,
    /// One verify row per labelled solution.
    pub solutions: Vec<Solution>,
    /// The folds and branch points of the branch file.
    pub events: Vec<AutoEvent>,
    /// The branch file's points (empty without one).
    pub branch: AutoBranch,
}

/// Whether `path` names AUTO-07p output: `s.NAME`, `b.NAME`, `fort.7`,
/// `fort.8`, or a TOML file with an `[auto]` mapping.
pub fn is_auto_input(path: &Path) -> bool {
    let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
    if solutions_beside(path).is_some() {
        return true;
    }
    name.to_ascii_lowercase().ends_with(".toml")
        && crate::io::read_text(path, crate::io::SCENE_FILE_LIMIT)
            .ok()
            .and_then(|t| t.parse::<toml::Table>().ok())
            .is_some_and(|t| t.contains_key("auto"))
}

/// The solutions file an AUTO file name stands for (b.NAME → s.NAME,
/// fort.7 → fort.8), None if the name is not AUTO's.
fn solutions_beside(path: &Path) -> Option<PathBuf> {
    let name = path.file_name()?.to_str()?;
    Some(match name {
        "fort.8" => path.into(),
        "fort.7" => path.with_file_name("fort.8"),
        _ if name.starts_with("s.") && name.len() > 2 => path.into(),
        _ if name.starts_with("b.") && name.len() > 2 => {
            path.with_file_name(format!("s.{}", &name[2..]))
        }
        _ => return None,
    })
}

/// Read AUTO-07p results: a TOML file with an `[auto]` mapping, or an AUTO
/// file with the mapping `map` (`--map KEY=VALUE`). `scene` overrides the
/// mapping's base scene.
pub fn read_auto_input(
    path: &Path,
    scene: Option<&Path>,
    map: &[String],
) -> Result<AutoInput, AutoError> {
    let map = match solutions_beside(path) {
        Some(solutions) => {
            let mut m = AutoMap::from_arguments(&solutions, map)?;
            if path.file_name() != solutions.file_name() && m.branch.is_none() {
                m.branch = Some(path.into());
            }
            m
        }
        None => {
            if !map.is_empty() {
                return Err(AutoError::Map {
                    source_name: "--map".into(),
                    field: map[0].clone(),
                    reason: format!("{} has its mapping in [auto]", path.display()),
                });
            }
            let text =
                crate::io::read_text(path, crate::io::SCENE_FILE_LIMIT).map_err(|source| {
                    AutoError::Io {
                        path: path.into(),
                        source,
                    }
                })?;
            AutoMap::from_toml(path, &text)?
        }
    };
    let scene_path = scene
        .map(Path::to_path_buf)
        .or(map.scene.clone())
        .ok_or_else(|| AutoError::Map {
            source_name: path.display().to_string(),
            field: "scene".into(),
            reason: "no base scene: give scene = \"path\" or --scene".into(),
        })?;
    let base = Scene::load(&scene_path)?;
    let strip = matches!(base.rod_model(None).law, Law::Strip { .. });
    let names: [&str; 6] = if strip {
        ["n0", "n0", "n0", "u1_0", "m2_0", "u3_0"]
    } else {
        ["n0", "n0", "n0", "m0", "m0", "m0"]
    };
    let mut slots = [0usize; 6];
    for k in 0..6 {
        slots[k] = map.unknowns[k].ok_or_else(|| AutoError::Map {
            source_name: path.display().to_string(),
            field: names[k].into(),
            reason: format!(
                "missing: which U indices are {} (the scene is a {})",
                if strip {
                    "n0, u1_0, m2_0, u3_0"
                } else {
                    "n0 and m0"
                },
                base.rod_model(None).law.name()
            ),
        })?;
    }
    let all = read_solutions_file(&map.solutions)?;
    let branch = match &map.branch {
        Some(b) => read_branch_file(b)?,
        None => AutoBranch::default(),
    };
    let labelled: Vec<&AutoSolution> = all.iter().filter(|s| s.label > 0).collect();
    if labelled.is_empty() {
        return Err(AutoError::Format {
            path: map.solutions.clone(),
            line: 1,
            field: "LAB".into(),
            reason: "no labelled solution in the file".into(),
        });
    }
    let mut solutions = Vec::with_capacity(labelled.len());
    for s in &labelled {
        solutions.push(row_of(&map, s, &slots)?);
        check_against_branch(&map, s, &branch)?;
    }
    let events = events_of(&map, &labelled, &branch);
    // a labelled fold is verified as one: at each N the discrete rod's own
    for e in &events {
        if let (PointType::Fold, Some(k), Some(parameter)) = (e.kind, e.row, e.parameter) {
            solutions[k].fold = Some(FoldClaim {
                parameter,
                tolerance: e.tolerance.unwrap_or(0.0),
            });
        }
    }
    Ok(AutoInput {
        map,
        scene: base,
        solutions,
        events,
        branch,
    })
}

/// The verify row of one labelled AUTO solution.
fn row_of(map: &AutoMap, s: &AutoSolution, slots: &[usize; 6]) -> Result<Solution, AutoError> {
    let bad = |field: String, reason: String| AutoError::Format {
        path: map.solutions.clone(),
        line: s.line,
        field,
        reason,
    };
    if s.t[0] != 0.0 {
        return Err(bad(
            "t".into(),
            format!(
                "LAB {}: the first mesh point is at t = {}, not 0",
                s.label, s.t[0]
            ),
        ));
    }
    let mut unknowns = [0.0; 6];
    let mut rounding = [0.0; 6];
    for k in 0..6 {
        let i = slots[k];
        if i > s.ndim {
            return Err(bad(
                format!("U({i})"),
                format!(
                    "LAB {}: the solution has NDIM = {} unknowns",
                    s.label, s.ndim
                ),
            ));
        }
        unknowns[k] = s.row(0)[i - 1];
        rounding[k] = s.u0_half_units[i - 1];
    }
    let mut parameters = Vec::new();
    let mut parameter_rounding = Vec::new();
    for m in &map.parameters {
        if m.par > s.par.len() {
            return Err(bad(
                format!("PAR({})", m.par),
                format!(
                    "{} is mapped to PAR({}), but the solution has NPAR = {}",
                    m.parameter.name(),
                    m.par,
                    s.par.len()
                ),
            ));
        }
        parameters.push((m.parameter, s.par[m.par - 1] * m.factor));
        parameter_rounding.push(s.par_half_units[m.par - 1] * m.factor);
    }
    Ok(Solution {
        name: format!("LAB {} {} (PT {})", s.label, s.kind.name(), s.point),
        parameters,
        parameter_rounding,
        unknowns,
        rounding,
        claims: Claims::default(),
        fold: None,
    })
}

/// The branch file's row of the solution's label, which must agree with the
/// solution on the continuation parameter (else the files are of two runs).
fn check_against_branch(
    map: &AutoMap,
    s: &AutoSolution,
    branch: &AutoBranch,
) -> Result<(), AutoError> {
    let Some(row) = branch
        .rows
        .iter()
        .find(|r| r.label == s.label && r.branch == s.branch)
    else {
        return Ok(());
    };
    let Some(&icp) = s.active.first() else {
        return Ok(());
    };
    let (Some(&v), Some(&h)) = (row.values.first(), row.half_units.first()) else {
        return Ok(());
    };
    let k = icp as usize;
    if icp < 1 || k > s.par.len() {
        return Ok(());
    }
    if (s.par[k - 1] - v).abs() > 2.0 * (h + s.par_half_units[k - 1]) {
        return Err(AutoError::Format {
            path: map.solutions.clone(),
            line: s.line,
            field: format!("PAR({icp})"),
            reason: format!(
                "LAB {}: {} here, but {} line {} has {v}: the two files are of different runs",
                s.label,
                s.par[k - 1],
                map.branch
                    .as_deref()
                    .unwrap_or(Path::new("the branch"))
                    .display(),
                row.line
            ),
        });
    }
    Ok(())
}

/// The branch's folds and branch points, each with AUTO's own location
/// tolerance in the continuation parameter.
fn events_of(map: &AutoMap, labelled: &[&AutoSolution], branch: &AutoBranch) -> Vec<AutoEvent> {
    // AUTO stops locating a special point when the next secant step is
    // shorter than EPSS (1 + √|DS DSMAX|) in its arclength (bvp.f90, LCSPBV)
    let arclength = match (branch.epss, branch.ds, branch.dsmax) {
        (Some(e), Some(ds), Some(dsmax)) => Some(e * (1.0 + (ds * dsmax).abs().sqrt())),
        _ => None,
    };
    let mut out = Vec::new();
    for r in &branch.rows {
        if r.label <= 0 || !matches!(r.kind, PointType::Fold | PointType::BranchPoint) {
            continue;
        }
        let row = labelled
            .iter()
            .position(|s| s.label == r.label && s.branch == r.branch);
        let solution = row.map(|k| labelled[k]);
        // the continuation parameter is the first active one, the branch's first column
        let icp = solution.and_then(|s| s.active.first().copied());
        let mapped = icp.and_then(|i| map.parameters.iter().find(|m| m.par as i64 == i));
        let value =
            r.values.first().copied().unwrap_or(f64::NAN) * mapped.map_or(1.0, |m| m.factor);
        let tolerance = match (arclength, solution, mapped) {
            (Some(ds), Some(s), Some(m)) => s
                .parameter_direction
                .first()
                .map(|d| ds * d.abs() * m.factor),
            _ => None,
        };
        out.push(AutoEvent {
            kind: r.kind,
            label: r.label,
            row,
            parameter: mapped.map(|m| m.parameter),
            value,
            tolerance,
        });
    }
    out
}
