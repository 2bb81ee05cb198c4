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
