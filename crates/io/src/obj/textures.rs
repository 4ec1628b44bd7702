//! Loading an MTL material's textures: each file once (by the path found), missing ones a
//! warning, and the composed images of [`maps`](super::maps) (alpha joined to the base colour,
//! normal maps from height maps, metallic-roughness) added to the scene's list.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use super::maps::{self, MapStatement, MaterialMaps, parse_map};
use super::paths;
use rt_core::error::{Error, Result};
use rt_core::scene::Texture;

/// The scene's textures as an MTL file's materials load them.
pub struct MtlTextures<'a> {
    /// The folder texture names are relative to (the MTL file's).
    pub dir: &'a Path,
    pub mtl_name: &'a Path,
    pub load: &'a dyn Fn(&Path) -> Result<Texture>,
    pub textures: Vec<Texture>,
    ids: HashMap<PathBuf, usize>,
}

/// What one material's textures come to: `map_Kd` (its index and statement, for the UV offset and
/// scale) and the other maps.
pub struct LoadedMaps {
    pub diffuse: Option<usize>,
    pub diffuse_statement: Option<MapStatement>,
    pub maps: MaterialMaps,
}

impl<'a> MtlTextures<'a> {
    pub fn new(
        dir: &'a Path,
        mtl_name: &'a Path,
        load: &'a dyn Fn(&Path) -> Result<Texture>,
    ) -> Self {
        MtlTextures {
            dir,
            mtl_name,
            load,
            textures: Vec::new(),
            ids: HashMap::new(),
        }
    }

    /// The texture a map statement names, loaded once; `None` (with a warning) where it is missing.
    fn file(&mut self, material: &str, statement: &MapStatement) -> Result<Option<usize>> {
        let found = paths::candidates(self.dir, &statement.file)
            .into_iter()
            .map(|path| ((self.load)(&path), path))
            .find(|(loaded, _)| !is_missing(loaded));
        let Some((loaded, path)) = found else {
            log::warn!(
                "{}: material '{material}': its texture '{}' is missing; the material has none",
                self.mtl_name.display(),
                statement.file
            );
            return Ok(None);
        };
        if let Some(&id) = self.ids.get(&path) {
            return Ok(Some(id));
        }
        self.textures.push(loaded?);
        self.ids.insert(path, self.textures.len() - 1);
        Ok(Some(self.textures.len() - 1))
    }

    fn add(&mut self, texture: Texture) -> usize {
        self.textures.push(texture);
        self.textures.len() - 1
    }

    /// Loads `m`'s maps (see [`maps`]).
    pub fn material(&mut self, m: &tobj::Material) -> Result<LoadedMaps> {
        let statement = |value: Option<&String>| value.and_then(|v| parse_map(v));
        let param = |key: &str| statement(m.unknown_param.get(key));
        let load = |this: &mut Self, s: &Option<MapStatement>| match s {
            Some(s) => this.file(&m.name, s),
            None => Ok(None),
        };
        let diffuse_statement = statement(m.diffuse_texture.as_ref());
        let diffuse = load(self, &diffuse_statement)?;
        let mut maps = MaterialMaps::default();

        let normal_statement = param("norm").or_else(|| statement(m.normal_texture.as_ref()));
        if let Some(id) = load(self, &normal_statement)? {
            let bump = normal_statement.as_ref().map_or(1.0, |s| s.bump);
            maps.normal = Some(if maps::is_height_map(&self.textures[id]) {
                let normal = maps::normal_map_from_height(&self.textures[id], bump);
                (self.add(normal), 1.0)
            } else {
                (id, bump)
            });
        }
        if let Some(id) = load(self, &statement(m.dissolve_texture.as_ref()))? {
            let base = diffuse.map(|d| &self.textures[d]);
            let joined = maps::with_alpha(base, &self.textures[id]);
            maps.base_with_alpha = Some(self.add(joined));
        }
        maps.emission = load(self, &param("map_Ke"))?;
        // map_Pr's roughness, else one from map_Ns (a shininess image multiplying Ns).
        let roughness = match load(self, &param("map_Pr"))? {
            Some(id) => Some(id),
            None => match load(self, &statement(m.shininess_texture.as_ref()))? {
                Some(id) => {
                    let ns = m.shininess.unwrap_or(1000.0);
                    let rough = maps::roughness_from_shininess(&self.textures[id], ns);
                    Some(self.add(rough))
                }
                None => None,
            },
        };
        let metallic = load(self, &param("map_Pm"))?;
        if roughness.is_some() || metallic.is_some() {
            let packed = maps::metallic_roughness(
                roughness.map(|i| &self.textures[i]),
                metallic.map(|i| &self.textures[i]),
            );
            maps.metallic_roughness = Some(self.add(packed));
            (maps.has_roughness_map, maps.has_metallic_map) =
                (roughness.is_some(), metallic.is_some());
        }

        maps.specular_color = load(self, &statement(m.specular_texture.as_ref()))?;

        let mut ignored: Vec<&str> = Vec::new();
        if m.ambient_texture.is_some() {
            ignored.push("map_Ka");
        }
        for key in ["disp", "decal", "refl", "map_Ps", "map_Pc", "map_Pcr"] {
            if m.unknown_param.contains_key(key) {
                ignored.push(key);
            }
        }
        if !ignored.is_empty() {
            log::warn!(
                "{}: material '{}': {} ignored (no such slot in rt's materials)",
                self.mtl_name.display(),
                m.name,
                ignored.join(", ")
            );
        }
        Ok(LoadedMaps {
            diffuse,
            diffuse_statement,
            maps,
        })
    }
}

/// A load that failed because the file is not there (as opposed to there and broken).
pub fn is_missing<T>(loaded: &Result<T>) -> bool {
    matches!(loaded, Err(Error::Io { source, .. }) if source.kind() == std::io::ErrorKind::NotFound)
}
