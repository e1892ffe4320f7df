//! Gazebo classic's OGRE material scripts (`materials/scripts/*.material`), read only as far as
//! rover needs them: which image a named material's first texture unit shows.
//!
//! Written here rather than taken from a crate: no crate on crates.io reads OGRE material
//! scripts, and rover needs one keyword of them.

use std::path::PathBuf;

/// Largest material script read.
const MAX_SCRIPT_BYTES: u64 = 4 << 20;

/// The image of material `name`'s first `texture` in the `.material` files of `dirs`, found
/// in one of `dirs` or in a `textures` folder beside one of them.
pub(crate) fn find_texture(name: &str, dirs: &[PathBuf]) -> Option<PathBuf> {
    let mut scripts: Vec<PathBuf> = dirs
        .iter()
        .filter_map(|d| std::fs::read_dir(d).ok())
        .flat_map(|entries| entries.filter_map(|e| e.ok().map(|e| e.path())))
        .filter(|p| p.extension().is_some_and(|e| e == "material"))
        .collect();
    scripts.sort();
    let image = scripts.iter().find_map(|script| {
        let bytes = crate::io::read_bounded(script, MAX_SCRIPT_BYTES).ok()?;
        texture_of(&String::from_utf8_lossy(&bytes), name)
    })?;
    dirs.iter()
        .flat_map(|d| [d.join(&image), d.join("../textures").join(&image)])
        .find(|p| p.is_file())
}

/// The first `texture` inside the block of `material NAME` (inheritance `material A : B`
/// allowed) in script `text`; comments (`//`) ignored.
pub(crate) fn texture_of(text: &str, name: &str) -> Option<String> {
    // Braces may touch their neighbours ("pass{"): space them out, then split on whitespace.
    let spaced: String = text
        .lines()
        .map(|l| l.split("//").next().unwrap_or(""))
        .flat_map(|l| l.chars().chain(['\n']))
        .flat_map(|c| match c {
            '{' | '}' => [' ', c, ' '],
            c => [c, '\0', '\0'],
        })
        .filter(|c| *c != '\0')
        .collect();
    let mut tokens = spaced.split_whitespace();
    while let Some(t) = tokens.next() {
        if t != "material" || tokens.next() != Some(name) {
            continue;
        }
        // Skip to the material's opening brace, then read its block.
        let mut depth = 0usize;
        for t in tokens.by_ref() {
            if t == "{" {
                depth = 1;
                break;
            }
        }
        if depth == 0 {
            return None;
        }
        while let Some(t) = tokens.next() {
            match t {
                "{" => depth += 1,
                "}" => {
                    depth -= 1;
                    if depth == 0 {
                        return None;
                    }
                }
                "texture" => return tokens.next().map(str::to_owned),
                _ => {}
            }
        }
        return None;
    }
    None
}

#[cfg(test)]
mod tests {
    use super::texture_of;

    #[test]
    fn the_named_materials_first_texture() {
        let script = "// signs\nmaterial Sign/Other\n{\n technique { pass { texture_unit { texture other.png } } }\n}\nmaterial Sign/Diffuse : Base/Lit\n{\n  receive_shadows off\n  technique\n  {\n    pass{\n      texture_unit\n      {\n        texture sign.png\n      }\n      texture_unit { texture second.png }\n    }\n  }\n}\n";
        assert_eq!(
            texture_of(script, "Sign/Diffuse").as_deref(),
            Some("sign.png")
        );
        assert_eq!(
            texture_of(script, "Sign/Other").as_deref(),
            Some("other.png")
        );
        assert_eq!(texture_of(script, "Sign/Missing"), None);
        assert_eq!(
            texture_of("material Plain { technique { pass { } } }", "Plain"),
            None
        );
    }
}
