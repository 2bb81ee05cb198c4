//! Files of shooting solutions for `knotrod verify`: TOML, JSON or CSV, one
//! solution per `[[solution]]` table, JSON object or CSV row. Each names the
//! scene parameters it was computed at (`phi_over_2pi = 0.802`, `K3 = 2.5`,
//! `end_tilt = 0.1`, …, set on top of the base scene), its six shooting
//! unknowns (`n0`, `m0` for a rod; `n0`, `u1_0`, `m2_0`, `u3_0` for a strip;
//! in CSV `n0_1 … n0_3`, `m0_1 … m0_3`), and optionally what its author claims
//! (`stable`, `lowest_omega2`, `twist`, `link`, `walled`, `knot`, `energy`).
//! The base scene is the file's `scene = "path"` (relative to the file) or
//! the command line's. Numbers are kept with their printed precision: half a
//! unit in their last digit is what rounding can explain.

use crate::model::rod::{Law, Parameter};
use crate::scene::{Scene, SceneError};
use crate::study::verify::{Claims, Printed, Solution};
use std::path::{Path, PathBuf};

/// Largest number of solutions in one file.
pub const MAX_SOLUTIONS: usize = 100_000;

/// The formats `knotrod verify` reads, for messages naming them.
pub const SUPPORTED_FORMATS: &str = "TOML (.toml: [[solution]] rows, or an [auto] mapping of \
     AUTO-07p files), JSON (.json), CSV (.csv), AUTO-07p's solutions s.NAME or fort.8 (with \
     --map, beside its branch b.NAME or fort.7)";

/// Why a file of solutions could not be used.
#[derive(Debug, thiserror::Error)]
pub enum VerifyFileError {
    /// Reading failed.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// The file is not valid TOML, JSON or CSV.
    #[error("{path}: {message}")]
    Parse {
        /// The file.
        path: PathBuf,
        /// The parser's message.
        message: String,
    },
    /// A field of a solution is missing, unknown or bad.
    #[error("{path}: {row}: {field}: {reason}")]
    Field {
        /// The file.
        path: PathBuf,
        /// Which solution ("solution 3", "line 4").
        row: String,
        /// The field.
        field: String,
        /// Why.
        reason: String,
    },
    /// No base scene was given.
    #[error("{path}: no scene: give `scene = \"path\"` in the file or --scene on the command line")]
    NoScene {
        /// The file.
        path: PathBuf,
    },
    /// Too many solutions.
    #[error("{path}: {count} solutions; the most read is {MAX_SOLUTIONS}")]
    TooMany {
        /// The file.
        path: PathBuf,
        /// How many.
        count: usize,
    },
    /// The base scene could not be read.
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// Not a format verify reads.
    #[error("{path}: not a format verify reads; supported: {}", SUPPORTED_FORMATS)]
    UnknownFormat {
        /// The file.
        path: PathBuf,
    },
}

/// A value as written: numbers keep half a unit of their last digit.
#[derive(Clone, Debug)]
enum Raw {
    Number(f64, f64),
    Bool(bool),
    Text(String),
    List(Vec<(f64, f64)>),
}

/// Half a unit in the last digit of a decimal literal ("8.7100" → 5e-5,
/// "-24.743" → 5e-4, "1.5e-3" → 5e-5, "12" → 0.5).
/// An exponent past the range of doubles gives 0 or infinity, which
/// [`usable`] refuses.
pub fn half_unit(literal: &str) -> f64 {
    let t = literal.trim().replace('_', "").to_ascii_lowercase();
    let (mantissa, exponent) = match t.split_once('e') {
        // clamped: past ±1000 the power is 0 or infinite either way
        Some((m, e)) => (
            m.to_string(),
            e.parse::<i64>()
                .unwrap_or(if e.starts_with('-') { -1000 } else { 1000 })
                .clamp(-1000, 1000),
        ),
        None => (t.clone(), 0),
    };
    let decimals = mantissa.split_once('.').map_or(0, |(_, f)| f.len() as i64);
    0.5 * 10f64.powi((exponent - decimals).clamp(-2000, 2000) as i32)
}

/// Why a number read with half-unit `u` cannot be used, if it cannot: it
/// must be finite, and neither it nor its last digit may underflow (a value
/// or a rounding below the smallest normal double, 2.2e-308, has lost its
/// digits: its rounding units would be 0/0).
fn usable(x: f64, u: f64) -> Result<(), String> {
    if !x.is_finite() {
        Err("a finite number".into())
    } else if (x != 0.0 && !x.is_normal()) || !u.is_normal() {
        Err(format!(
            "the number underflows: it or its last digit is below {:e}, the smallest normal \
             double, so its printed precision is lost",
            f64::MIN_POSITIVE
        ))
    } else {
        Ok(())
    }
}

/// A decimal literal's value and half-unit (TOML's digit separators `_` are
/// removed before, by the TOML reader only: in CSV "3_1" is a knot's name).
fn number(text: &str) -> Option<(f64, f64)> {
    let v: f64 = text.trim().parse().ok()?;
    Some((v, half_unit(text)))
}

type Row = (String, Vec<(String, Raw)>);

fn toml_raw(v: &toml::de::DeValue) -> Option<Raw> {
    use toml::de::DeValue;
    Some(match v {
        DeValue::Float(f) => {
            let (x, u) = number(&f.as_str().replace('_', ""))?;
            Raw::Number(x, u)
        }
        DeValue::Integer(i) if i.radix() == 10 => {
            let (x, u) = number(&i.as_str().replace('_', ""))?;
            Raw::Number(x, u)
        }
        DeValue::Boolean(b) => Raw::Bool(*b),
        DeValue::String(s) => Raw::Text(s.to_string()),
        DeValue::Array(a) => Raw::List(
            a.into_iter()
                .map(|x| match toml_raw(x.get_ref())? {
                    Raw::Number(x, u) => Some((x, u)),
                    _ => None,
                })
                .collect::<Option<Vec<_>>>()?,
        ),
        _ => return None,
    })
}

fn parse_toml(path: &Path, text: &str) -> Result<(Option<String>, Vec<Row>), VerifyFileError> {
    let parse_error = |message: String| VerifyFileError::Parse {
        path: path.into(),
        message,
    };
    let table = toml::de::DeTable::parse(text).map_err(|e| parse_error(e.to_string()))?;
    let mut scene = None;
    let mut rows = Vec::new();
    for (key, value) in table.get_ref().iter() {
        match key.get_ref().as_ref() {
            "scene" => {
                scene = Some(
                    value
                        .get_ref()
                        .as_str()
                        .ok_or_else(|| parse_error("scene: a path (a string)".into()))?
                        .to_string(),
                )
            }
            "solution" => {
                let list = value.get_ref().as_array().ok_or_else(|| {
                    parse_error("solution: an array of tables [[solution]]".into())
                })?;
                for (k, item) in list.into_iter().enumerate() {
                    let row = format!("solution {}", k + 1);
                    let table = item
                        .get_ref()
                        .as_table()
                        .ok_or_else(|| parse_error(format!("{row}: a table of fields")))?;
                    let mut fields = Vec::new();
                    for (name, v) in table.iter() {
                        let name = name.get_ref().to_string();
                        let raw = toml_raw(v.get_ref()).ok_or_else(|| VerifyFileError::Field {
                            path: path.into(),
                            row: row.clone(),
                            field: name.clone(),
                            reason: "not a number, a list of numbers, a boolean or a string".into(),
                        })?;
                        fields.push((name, raw));
                    }
                    rows.push((row, fields));
                }
            }
            other => {
                return Err(parse_error(format!(
                    "unknown key `{other}` (expected scene and [[solution]])"
                )));
            }
        }
    }
    Ok((scene, rows))
}

fn json_raw(raw: &serde_json::value::RawValue) -> Option<Raw> {
    let t = raw.get().trim();
    Some(match t.chars().next()? {
        '[' => {
            let items: Vec<Box<serde_json::value::RawValue>> = serde_json::from_str(t).ok()?;
            Raw::List(
                items
                    .iter()
                    .map(|x| number(x.get()))
                    .collect::<Option<Vec<_>>>()?,
            )
        }
        '"' => Raw::Text(serde_json::from_str(t).ok()?),
        't' | 'f' => Raw::Bool(serde_json::from_str(t).ok()?),
        _ => {
            let (x, u) = number(t)?;
            Raw::Number(x, u)
        }
    })
}

/// A JSON object's fields in the order written, a name given twice kept
/// twice (a map would keep only the last).
struct Fields(Vec<(String, Box<serde_json::value::RawValue>)>);

impl<'de> serde::Deserialize<'de> for Fields {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Visit;
        impl<'de> serde::de::Visitor<'de> for Visit {
            type Value = Fields;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("an object")
            }
            fn visit_map<A: serde::de::MapAccess<'de>>(self, mut m: A) -> Result<Fields, A::Error> {
                let mut fields = Vec::new();
                while let Some(entry) = m.next_entry()? {
                    fields.push(entry);
                }
                Ok(Fields(fields))
            }
        }
        d.deserialize_map(Visit)
    }
}

fn parse_json(path: &Path, text: &str) -> Result<(Option<String>, Vec<Row>), VerifyFileError> {
    let parse_error = |message: String| VerifyFileError::Parse {
        path: path.into(),
        message,
    };
    // each field is read as raw text, for its printed precision
    let top: Fields = serde_json::from_str(text).map_err(|e| parse_error(e.to_string()))?;
    let mut scene = None;
    let mut list: Option<Vec<Fields>> = None;
    for (key, value) in &top.0 {
        match key.as_str() {
            "scene" if scene.is_some() => return Err(parse_error("scene is given twice".into())),
            "scene" => {
                scene = Some(
                    serde_json::from_str::<String>(value.get())
                        .map_err(|_| parse_error("scene: a path (a string)".into()))?,
                )
            }
            "solution" if list.is_some() => {
                return Err(parse_error("solution is given twice".into()));
            }
            "solution" => {
                list = Some(
                    serde_json::from_str(value.get())
                        .map_err(|e| parse_error(format!("solution: a list of objects ({e})")))?,
                )
            }
            other => {
                return Err(parse_error(format!(
                    "unknown key `{other}` (expected scene and solution)"
                )));
            }
        }
    }
    let mut rows = Vec::new();
    for (k, fields) in list.iter().flatten().enumerate() {
        let row = format!("solution {}", k + 1);
        let mut out = Vec::new();
        for (name, value) in &fields.0 {
            let raw = json_raw(value).ok_or_else(|| VerifyFileError::Field {
                path: path.into(),
                row: row.clone(),
                field: name.clone(),
                reason: "not a number, a list of numbers, a boolean or a string".into(),
            })?;
            out.push((name.clone(), raw));
        }
        rows.push((row, out));
    }
    Ok((scene, rows))
}

fn parse_csv(path: &Path, text: &str) -> Result<(Option<String>, Vec<Row>), VerifyFileError> {
    let parse_error = |message: String| VerifyFileError::Parse {
        path: path.into(),
        message,
    };
    let mut reader = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .comment(Some(b'#'))
        .from_reader(text.as_bytes());
    let header: Vec<String> = reader
        .headers()
        .map_err(|e| parse_error(e.to_string()))?
        .iter()
        .map(str::to_string)
        .collect();
    for (k, name) in header.iter().enumerate() {
        if header[..k].contains(name) {
            return Err(VerifyFileError::Field {
                path: path.into(),
                row: "line 1 (the header)".into(),
                field: name.clone(),
                reason: "two columns have this name".into(),
            });
        }
    }
    let mut rows = Vec::new();
    for record in reader.records() {
        let record = record.map_err(|e| parse_error(e.to_string()))?;
        let line = record.position().map_or(0, |p| p.line());
        let row = format!("line {line}");
        let mut fields = Vec::new();
        for (name, cell) in header.iter().zip(record.iter()) {
            if cell.is_empty() {
                continue;
            }
            let raw = match cell.to_ascii_lowercase().as_str() {
                "true" => Raw::Bool(true),
                "false" => Raw::Bool(false),
                _ => match number(cell) {
                    Some((x, u)) => Raw::Number(x, u),
                    None => Raw::Text(cell.to_string()),
                },
            };
            fields.push((name.clone(), raw));
        }
        rows.push((row, fields));
    }
    Ok((None, rows))
}

/// The solutions of `path` (TOML, JSON or CSV by its extension) and their base
/// scene (`scene` overrides the file's `scene = "…"`).
pub fn read_solutions(
    path: &Path,
    scene: Option<&Path>,
) -> Result<(Scene, Vec<Solution>), VerifyFileError> {
    let text = crate::io::read_text(path, crate::io::SCENE_FILE_LIMIT).map_err(|source| {
        VerifyFileError::Io {
            path: path.into(),
            source,
        }
    })?;
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    let (named, rows) = match ext.as_str() {
        "json" => parse_json(path, &text)?,
        "csv" => parse_csv(path, &text)?,
        "toml" => parse_toml(path, &text)?,
        _ => return Err(VerifyFileError::UnknownFormat { path: path.into() }),
    };
    if rows.len() > MAX_SOLUTIONS {
        return Err(VerifyFileError::TooMany {
            path: path.into(),
            count: rows.len(),
        });
    }
    let scene_path = match (scene, named) {
        (Some(p), _) => p.to_path_buf(),
        (None, Some(p)) => path.parent().unwrap_or(Path::new(".")).join(p),
        (None, None) => return Err(VerifyFileError::NoScene { path: path.into() }),
    };
    let base = Scene::load(&scene_path)?;
    let law = base.rod_model(None).law;
    let solutions = rows
        .into_iter()
        .enumerate()
        .map(|(k, (row, fields))| solution(path, k, &row, fields, law))
        .collect::<Result<Vec<_>, _>>()?;
    if solutions.is_empty() {
        return Err(VerifyFileError::Parse {
            path: path.into(),
            message: "no solution in the file".into(),
        });
    }
    Ok((base, solutions))
}

fn solution(
    path: &Path,
    index: usize,
    row: &str,
    fields: Vec<(String, Raw)>,
    law: Law,
) -> Result<Solution, VerifyFileError> {
    let mut reader = RowReader {
        path,
        row,
        law,
        strip: matches!(law, Law::Strip { .. }),
        name: format!("row {}", index + 1),
        parameters: Vec::new(),
        parameter_rounding: Vec::new(),
        unknowns: [None; 6],
        set_by: [None; 6],
        claims: Claims::default(),
    };
    for (k, (field, raw)) in fields.iter().enumerate() {
        if fields[..k].iter().any(|(g, _)| g == field) {
            return Err(reader.bad(field, "given twice".into()));
        }
        reader.read(field, raw)?;
    }
    reader.finish()
}

/// One row's fields as they are read: the unknowns, parameters and claims so far.
struct RowReader<'a> {
    path: &'a Path,
    row: &'a str,
    law: Law,
    strip: bool,
    name: String,
    parameters: Vec<(Parameter, f64)>,
    parameter_rounding: Vec<f64>,
    /// n0 then m0 (rod) or u1_0, m2_0, u3_0 (strip), each with its rounding.
    unknowns: [Option<(f64, f64)>; 6],
    /// The field that set each unknown: one given twice (n0 and n0_1) is refused.
    set_by: [Option<&'a str>; 6],
    claims: Claims,
}

impl<'a> RowReader<'a> {
    fn bad(&self, field: &str, reason: String) -> VerifyFileError {
        VerifyFileError::Field {
            path: self.path.into(),
            row: self.row.into(),
            field: field.into(),
            reason,
        }
    }

    fn finite(&self, field: &str, raw: &Raw) -> Result<(f64, f64), VerifyFileError> {
        match raw {
            Raw::Number(x, u) => usable(*x, *u)
                .map(|()| (*x, *u))
                .map_err(|why| self.bad(field, why)),
            _ => Err(self.bad(field, "a finite number".into())),
        }
    }

    fn printed(&self, field: &str, raw: &Raw) -> Result<Option<Printed>, VerifyFileError> {
        let (value, half_unit) = self.finite(field, raw)?;
        Ok(Some(Printed { value, half_unit }))
    }

    fn flag(&self, field: &str, raw: &Raw) -> Result<Option<bool>, VerifyFileError> {
        match raw {
            Raw::Bool(b) => Ok(Some(*b)),
            _ => Err(self.bad(field, "true or false".into())),
        }
    }

    fn set(
        &mut self,
        field: &'a str,
        slot: usize,
        value: (f64, f64),
    ) -> Result<(), VerifyFileError> {
        if let Some(other) = self.set_by[slot].replace(field) {
            return Err(self.bad(
                field,
                format!("the unknown is given twice (by {other} and {field})"),
            ));
        }
        self.unknowns[slot] = Some(value);
        Ok(())
    }

    /// A vector unknown [x, y, z] into the slots from `base`.
    fn vector(&mut self, field: &'a str, raw: &Raw, base: usize) -> Result<(), VerifyFileError> {
        match raw {
            Raw::List(v) if v.len() == 3 => {
                for (c, &(x, u)) in v.iter().enumerate() {
                    usable(x, u)
                        .map_err(|why| self.bad(field, format!("component {}: {why}", c + 1)))?;
                    self.set(field, base + c, (x, u))?;
                }
                Ok(())
            }
            _ => Err(self.bad(field, "three finite numbers [x, y, z]".into())),
        }
    }

    fn read(&mut self, field: &'a str, raw: &Raw) -> Result<(), VerifyFileError> {
        // the component's index in n0_k / m0_k
        let component = || field.as_bytes()[3] as usize - b'1' as usize;
        match field {
            "name" => match raw {
                Raw::Text(t) => self.name = t.clone(),
                Raw::Number(x, _) => self.name = format!("{x}"),
                _ => return Err(self.bad(field, "a name".into())),
            },
            "n0" => self.vector(field, raw, 0)?,
            "m0" if !self.strip => self.vector(field, raw, 3)?,
            "m0" => {
                return Err(self.bad(
                    field,
                    "the scene is a strip: give its unknowns u1_0, m2_0, u3_0 with n0".into(),
                ));
            }
            "n0_1" | "n0_2" | "n0_3" => {
                let value = self.finite(field, raw)?;
                self.set(field, component(), value)?
            }
            "m0_1" | "m0_2" | "m0_3" if !self.strip => {
                let value = self.finite(field, raw)?;
                self.set(field, 3 + component(), value)?
            }
            "u1_0" | "m2_0" | "u3_0" if !self.strip => {
                return Err(self.bad(
                    field,
                    "the scene is a rod: give its unknowns n0 and m0 (material frame at s = 0)"
                        .into(),
                ));
            }
            "u1_0" | "m2_0" | "u3_0" => {
                let slot = match field {
                    "u1_0" => 3,
                    "m2_0" => 4,
                    _ => 5,
                };
                let value = self.finite(field, raw)?;
                self.set(field, slot, value)?
            }
            "stable" => self.claims.stable = self.flag(field, raw)?,
            "walled" => self.claims.walled = self.flag(field, raw)?,
            "lowest_omega2" => self.claims.lowest_omega2 = self.printed(field, raw)?,
            "twist" => self.claims.twist = self.printed(field, raw)?,
            "link" => self.claims.link = self.printed(field, raw)?,
            "energy" => self.claims.energy = self.printed(field, raw)?,
            "knot" => match raw {
                Raw::Text(t) => self.claims.knot = Some(t.clone()),
                _ => {
                    return Err(self.bad(field, "a knot name such as \"3_1\" or \"0_1\"".into()));
                }
            },
            _ => self.parameter(field, raw)?,
        }
        Ok(())
    }

    fn parameter(&mut self, field: &str, raw: &Raw) -> Result<(), VerifyFileError> {
        let Some(p) = Parameter::named(field) else {
            return Err(self.bad(
                field,
                "unknown field (a scene parameter such as z_star, delta, phi_over_2pi, \
                 end_tilt, K3, weight; the unknowns n0, m0 or u1_0, m2_0, u3_0; or a \
                 claim: stable, lowest_omega2, twist, link, walled, knot, energy)"
                    .into(),
            ));
        };
        if let Some(why) = absent_from(p, self.law) {
            return Err(self.bad(field, why.into()));
        }
        let (v, u) = self.finite(field, raw)?;
        if self.parameters.iter().any(|(q, _)| *q == p) {
            return Err(self.bad(field, format!("{} is given twice", p.name())));
        }
        self.parameters.push((p, v));
        self.parameter_rounding.push(u);
        Ok(())
    }

    fn finish(self) -> Result<Solution, VerifyFileError> {
        let names: [&str; 6] = if self.strip {
            ["n0_1", "n0_2", "n0_3", "u1_0", "m2_0", "u3_0"]
        } else {
            ["n0_1", "n0_2", "n0_3", "m0_1", "m0_2", "m0_3"]
        };
        let mut values = [0.0; 6];
        let mut rounding = [0.0; 6];
        for k in 0..6 {
            let (v, u) = self.unknowns[k].ok_or_else(|| self.bad(names[k], "missing".into()))?;
            values[k] = v;
            rounding[k] = u;
        }
        Ok(Solution {
            name: self.name,
            parameters: self.parameters,
            parameter_rounding: self.parameter_rounding,
            unknowns: values,
            rounding,
            claims: self.claims,
            fold: None,
        })
    }
}

/// Why the law has no parameter `p`, if it has none.
fn absent_from(p: Parameter, law: Law) -> Option<&'static str> {
    match (p, law) {
        (Parameter::K2, Law::Strip { .. }) => {
            Some("the strip law has no K2 (u2 = 0 is a constraint): the row sets no stiffness")
        }
        (Parameter::K2, Law::Unbendable) => {
            Some("the unbendable rod has no K2 (u2 = 0 is a constraint): the row sets no stiffness")
        }
        (Parameter::K3, Law::Strip { .. }) => {
            Some("the strip law has no K3 (bending and twisting do not separate)")
        }
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn printed_precision_is_kept() {
        assert_eq!(half_unit("8.7100"), 5e-5);
        assert_eq!(half_unit("-24.743"), 0.5e-3);
        assert!((half_unit("1.5e-3") - 5e-5).abs() < 1e-20);
        assert_eq!(half_unit("12"), 0.5);
        assert_eq!(half_unit("1_000.25"), 5e-3);
    }
}
