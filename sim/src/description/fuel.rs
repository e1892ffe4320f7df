//! Gazebo Fuel model URIs in worlds (`https://fuel.gazebosim.org/1.0/OWNER/models/NAME[/VERSION]`),
//! resolved without the network: Fuel's Sun and Ground Plane are rover's built-in sun and
//! ground, its Standing person and Walking person rover's people; any other model comes from a model folder of that name on the model path
//! (`--model-path`, `GZ_SIM_RESOURCE_PATH`, `GAZEBO_MODEL_PATH`) or from the local Fuel cache
//! gz-sim downloads into (`GZ_FUEL_CACHE_PATH`, else `~/.gz/fuel`). rover never fetches at run
//! time: a model found nowhere is an error naming the URI and every place looked at.

use std::path::{Path, PathBuf};

use crate::description::resource::ResourcePaths;

/// A Fuel model URI's parts.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct FuelUri {
    /// The server (`fuel.gazebosim.org`).
    pub host: String,
    /// The owner (`OpenRobotics`).
    pub owner: String,
    /// The model's name, percent-decoded (`Ground Plane`).
    pub name: String,
    /// The version, when the URI names one.
    pub version: Option<String>,
}

/// The parts of a Fuel model URI; `None` for any other URI.
pub(crate) fn parse(uri: &str) -> Option<FuelUri> {
    let rest = uri
        .strip_prefix("https://")
        .or_else(|| uri.strip_prefix("http://"))?;
    let mut parts = rest.split('/');
    let host = parts.next()?.to_owned();
    let segments: Vec<&str> = parts.filter(|s| !s.is_empty()).collect();
    // [api version,] owner, "models", name, [version, ...]
    let at = segments
        .iter()
        .position(|s| s.eq_ignore_ascii_case("models"))?;
    let owner = segments.get(at.checked_sub(1)?)?;
    let name = segments.get(at + 1)?;
    let version = segments
        .get(at + 2)
        .filter(|v| v.chars().all(|c| c.is_ascii_digit()) || **v == "tip")
        .map(|v| (*v).to_owned());
    Some(FuelUri {
        host,
        owner: decode(owner),
        name: decode(name),
        version,
    })
}

/// `%20` and the like decoded.
fn decode(s: &str) -> String {
    let bytes = s.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%'
            && let Some(v) = s
                .get(i + 1..i + 3)
                .and_then(|h| u8::from_str_radix(h, 16).ok())
        {
            out.push(v);
            i += 3;
            continue;
        }
        out.push(bytes[i]);
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// The built-in a Fuel model is (`sun`, `ground_plane`, `person_standing`, `person_walking`:
/// the names the `model://` forms have), if it is one.
pub(crate) fn builtin(uri: &FuelUri) -> Option<&'static str> {
    match uri
        .name
        .to_ascii_lowercase()
        .replace([' ', '-'], "_")
        .as_str()
    {
        "sun" => Some("sun"),
        "ground_plane" => Some("ground_plane"),
        "standing_person" => Some("person_standing"),
        "walking_person" => Some("person_walking"),
        _ => None,
    }
}

/// The local folder of Fuel model `uri`, or an error naming every place looked at.
pub(crate) fn find_local(uri: &FuelUri, resources: &ResourcePaths) -> Result<PathBuf, String> {
    let mut looked = Vec::new();
    let names = [
        uri.name.clone(),
        uri.name.to_ascii_lowercase(),
        uri.name.to_ascii_lowercase().replace(' ', "_"),
    ];
    for root in &resources.model_search {
        for name in &names {
            let dir = root.join(name);
            if is_model(&dir) {
                return Ok(dir);
            }
        }
        looked.push(root.display().to_string());
    }
    for cache in cache_roots() {
        let models = cache
            .join(&uri.host)
            .join(uri.owner.to_ascii_lowercase())
            .join("models")
            .join(uri.name.to_ascii_lowercase());
        looked.push(models.display().to_string());
        if let Some(dir) = cached_version(&models, uri.version.as_deref()) {
            return Ok(dir);
        }
    }
    Err(format!(
        "Fuel model \"{}\" by {} is not on this machine and rover does not download at run time; looked in {} (put the model's folder, named \"{}\", on --model-path or GZ_SIM_RESOURCE_PATH, or fetch it once with `gz fuel download -u URI`)",
        uri.name,
        uri.owner,
        if looked.is_empty() {
            "no model path".to_owned()
        } else {
            looked.join(", ")
        },
        uri.name
    ))
}

fn is_model(dir: &Path) -> bool {
    dir.join("model.config").is_file() || dir.join("model.sdf").is_file()
}

/// Where gz-sim keeps downloaded Fuel models.
fn cache_roots() -> Vec<PathBuf> {
    let mut out = Vec::new();
    for var in ["GZ_FUEL_CACHE_PATH", "IGN_FUEL_CACHE_PATH"] {
        if let Some(v) = std::env::var_os(var).filter(|v| !v.is_empty()) {
            out.push(PathBuf::from(v));
        }
    }
    if let Some(home) = std::env::var_os("HOME").filter(|v| !v.is_empty()) {
        out.push(Path::new(&home).join(".gz/fuel"));
        out.push(Path::new(&home).join(".ignition/fuel"));
    }
    out
}

/// The cached version folder: the one named, else the highest number.
fn cached_version(models: &Path, version: Option<&str>) -> Option<PathBuf> {
    if let Some(v) = version.filter(|v| *v != "tip") {
        let dir = models.join(v);
        return is_model(&dir).then_some(dir);
    }
    let entries = std::fs::read_dir(models).ok()?;
    entries
        .filter_map(|e| e.ok())
        .filter_map(|e| {
            let n: u64 = e.file_name().to_str()?.parse().ok()?;
            is_model(&e.path()).then(|| (n, e.path()))
        })
        .max_by_key(|(n, _)| *n)
        .map(|(_, p)| p)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fuel_uris_name_owner_model_and_version() {
        let u = parse("https://fuel.gazebosim.org/1.0/OpenRobotics/models/Ground Plane");
        assert_eq!(
            u,
            Some(FuelUri {
                host: "fuel.gazebosim.org".to_owned(),
                owner: "OpenRobotics".to_owned(),
                name: "Ground Plane".to_owned(),
                version: None,
            })
        );
        let u = parse("https://fuel.gazebosim.org/1.0/OpenRobotics/models/Ground%20Plane/3");
        assert_eq!(u.as_ref().map(|u| u.name.as_str()), Some("Ground Plane"));
        assert_eq!(u.as_ref().and_then(|u| u.version.as_deref()), Some("3"));
        assert_eq!(u.as_ref().and_then(builtin), Some("ground_plane"));
        let sun = parse("https://fuel.ignitionrobotics.org/1.0/openrobotics/models/sun");
        assert_eq!(sun.as_ref().and_then(builtin), Some("sun"));
        assert_eq!(parse("model://sun"), None);
        assert_eq!(parse("https://example.com/page"), None);
    }

    #[test]
    fn a_missing_fuel_model_says_where_it_looked() -> std::io::Result<()> {
        let tmp = tempfile::tempdir()?;
        let uri = parse("https://fuel.gazebosim.org/1.0/OpenRobotics/models/Cafe table")
            .ok_or_else(|| std::io::Error::other("not a Fuel URI"))?;
        let resources = ResourcePaths::default().with_model_path(tmp.path());
        let err = find_local(&uri, &resources).err().unwrap_or_default();
        assert!(err.contains("\"Cafe table\""), "{err}");
        assert!(err.contains(&tmp.path().display().to_string()), "{err}");
        std::fs::create_dir_all(tmp.path().join("cafe_table"))?;
        std::fs::write(tmp.path().join("cafe_table/model.sdf"), "<sdf/>")?;
        assert_eq!(
            find_local(&uri, &resources).ok(),
            Some(tmp.path().join("cafe_table"))
        );
        Ok(())
    }
}
