//! rtbench-scenes: the scene model of rtbench and where scenes come from.
//!
//! - [`spd`]: the eleven Standard Procedural Database programs (SPD 3.14), ported so that they
//!   print the same NFF as the C originals. Generators stream into a [`Sink`].
//! - [`nff`]: NFF reading (user scenes, fixtures) and writing.
//! - [`model`]: [`Scene`] and its records, exactly the SPD primitive types.
//! - [`triangulate`]: polygons to triangles (ear clipping; gears' faces are concave).
//!
//! ```
//! use rtbench_scenes::{spd, sink::CountingSink};
//! let mut counter = CountingSink::default();
//! spd::generate(spd::Program::Tetra, &spd::Options::standard(spd::Program::Tetra), &mut counter).unwrap();
//! assert_eq!(counter.counts.polygon, 4096);
//! ```

pub mod mesh;
pub mod model;
pub mod nff;
pub mod room;
pub mod sink;
pub mod spd;
pub mod triangulate;
pub mod validate;

pub use model::{Bounds, Light, Material, Object, Scene, Shape, ShapeRef, View};
pub use sink::{CountingSink, SceneCollector, Sink};

/// Generates an SPD program into a [`Scene`] in memory.
pub fn generate_scene(program: spd::Program, opts: &spd::Options) -> Result<Scene, spd::SpdError> {
    let mut c = SceneCollector::default();
    spd::generate(program, opts, &mut c)?;
    let mut scene = c.scene;
    scene.name = format!("{}{}", program.name(), opts.size_factor);
    Ok(scene)
}
