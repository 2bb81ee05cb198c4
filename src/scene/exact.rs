//! Arrays of exactly N numbers. TOML's reader fills `[f64; N]` from the
//! first N entries of a longer list and drops the rest; these read every
//! entry and refuse a wrong count.

use serde::de::Error;
use serde::{Deserialize, Deserializer};

fn to_array<E: Error, const N: usize>(v: Vec<f64>) -> Result<[f64; N], E> {
    let n = v.len();
    v.try_into()
        .map_err(|_| E::invalid_length(n, &format!("exactly {N} numbers").as_str()))
}

/// `[f64; N]`.
pub fn array<'de, D: Deserializer<'de>, const N: usize>(d: D) -> Result<[f64; N], D::Error> {
    to_array(Vec::<f64>::deserialize(d)?)
}

/// `Option<[f64; N]>`.
pub fn option<'de, D: Deserializer<'de>, const N: usize>(
    d: D,
) -> Result<Option<[f64; N]>, D::Error> {
    Option::<Vec<f64>>::deserialize(d)?
        .map(to_array)
        .transpose()
}

/// `Vec<[f64; N]>`.
pub fn list<'de, D: Deserializer<'de>, const N: usize>(d: D) -> Result<Vec<[f64; N]>, D::Error> {
    Vec::<Vec<f64>>::deserialize(d)?
        .into_iter()
        .map(to_array)
        .collect()
}

/// `Option<Vec<[f64; N]>>`.
pub fn option_list<'de, D: Deserializer<'de>, const N: usize>(
    d: D,
) -> Result<Option<Vec<[f64; N]>>, D::Error> {
    Option::<Vec<Vec<f64>>>::deserialize(d)?
        .map(|l| l.into_iter().map(to_array).collect())
        .transpose()
}

/// Natural strains: exactly three numbers [û1, û2, û3], a table of rows of
/// exactly four [s, û1, û2, û3], or `{ end_deflection = d }`: the plastified
/// rod's uniform û1 whose stress-free arc, held at one end, ends d·L off the
/// held end's tangent (`model::natural::arc_curvature`).
pub fn natural<'de, D: Deserializer<'de>>(
    d: D,
) -> Result<crate::model::natural::NaturalStrains, D::Error> {
    use crate::model::natural::NaturalStrains;
    #[derive(Deserialize)]
    #[serde(untagged)]
    enum Raw {
        Triple(Vec<f64>),
        Rows(Vec<Vec<f64>>),
        Arc(Arc),
    }
    #[derive(Deserialize)]
    #[serde(deny_unknown_fields)]
    struct Arc {
        end_deflection: f64,
    }
    match Raw::deserialize(d).map_err(|_| {
        D::Error::custom(
            "natural_strains: expected [û1, û2, û3], a table of rows [s, û1, û2, û3] or { end_deflection = d }",
        )
    })? {
        Raw::Arc(Arc { end_deflection }) => {
            crate::model::natural::arc_curvature(end_deflection)
                .map(|u| NaturalStrains::Constant([u, 0.0, 0.0]))
                .ok_or_else(|| {
                    D::Error::custom(format!(
                        "natural_strains.end_deflection: {end_deflection} is not a deflection an arc reaches (|d| ≤ {} of the length)",
                        crate::model::natural::MOST_END_DEFLECTION
                    ))
                })
        }
        Raw::Triple(v) => to_array(v).map(NaturalStrains::Constant),
        Raw::Rows(rows) => rows
            .into_iter()
            .map(to_array)
            .collect::<Result<_, _>>()
            .map(NaturalStrains::Table),
    }
}
