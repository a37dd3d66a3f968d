//! Procedural meshes with known volume, area and inertia: test cases for every stage and the
//! building blocks of the generated fixtures. All are closed and outward oriented unless said.
//!
//! Rooms: [`solids`] (primitives, lofts, revolutions), [`objects`] (bowl, mug, shelf, tray,
//! basket, pen, fruit), [`texture`] (UVs, materials, procedural textures).

pub mod objects;
pub mod solids;
pub mod texture;

pub use objects::*;
pub use solids::*;
pub use texture::*;

#[cfg(test)]
mod tests;
