//! # Lists sent with their capacity
//!
//! serde's `with` for a list whose capacity the lab counts as the memory it
//! takes (a grid's cells, the back end's tables): written with its
//! capacity and read back with the same, so a mapping that came home
//! reports the bytes it would have at home, and grows as it would have.
//!
//! Used as `#[serde(with = "crate::slam::keep_capacity")]` by the grid and
//! the robot graph, whose bytes [`super::handoff`] sends between threads.

use serde::{Deserialize, Deserializer, Serialize, Serializer};

pub fn serialize<S: Serializer, T: Serialize>(v: &Vec<T>, s: S) -> Result<S::Ok, S::Error> {
    (v.capacity() as u64, v).serialize(s)
}

pub fn deserialize<'de, D, T>(d: D) -> Result<Vec<T>, D::Error>
where
    D: Deserializer<'de>,
    T: Deserialize<'de>,
{
    let (capacity, v): (u64, Vec<T>) = Deserialize::deserialize(d)?;
    let mut out = Vec::with_capacity((capacity as usize).max(v.len()));
    out.extend(v);
    Ok(out)
}
