//! Render passes, one per file. Each owns its pipeline and targets and draws the shared
//! [`crate::render::scene::Scene`]; a new output (object ids, depth) is a new file here plus
//! one line where the renderer records its passes.

pub(crate) mod colour;
