//! Render passes, one per file. Each owns its pipeline and targets and draws the shared
//! [`crate::render::scene::Scene`]; a new output (depth, ...) is a new file here plus one line
//! where the renderer records its passes. The colour pass also writes the instance-id image
//! (same draw); the silhouette pass gives each labelled thing's unoccluded pixel count.

pub(crate) mod colour;
pub(crate) mod silhouette;
