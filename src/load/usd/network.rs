//! UsdShade networks as a renderer reads them: which material a prim is bound to
//! (`UsdShadeMaterialBindingAPI::ComputeBoundMaterial`, full purpose), which shader drives
//! a material's surface (`UsdShadeMaterial::ComputeSurfaceSource`), and what feeds a
//! shader input once connections through NodeGraph outputs and material or NodeGraph
//! interface inputs are followed (`UsdShadeInput::GetValueProducingAttributes`). See the
//! UsdShade schema documentation, "Material binding" and "Connections".

use std::collections::HashMap;

use openusd::{sdf, usd};

use super::UsdLoader;
use super::value::as_token;

/// Longest chain of connections followed; longer chains are cycles or hostile.
const MAX_HOPS: usize = 64;

/// The purpose a final-frame renderer resolves bindings for, before all-purpose.
const PURPOSE: &str = "full";

/// What feeds a shader input.
pub(super) enum Source {
    /// An output of a shader node: the node's prim and the output's name (`outputs:rgb`).
    Node { prim: sdf::Path, output: String },
    /// A value authored on the input itself or on the interface input it reads.
    Value(sdf::Value),
}

impl UsdLoader {
    /// The material bound to `prim` for the full purpose, walking the prim and its ancestors:
    /// at each prim a collection binding whose collection includes `prim` beats a direct
    /// one, the closest prim's binding wins unless an ancestor's is
    /// `strongerThanDescendants`, and the full purpose is tried over all ancestors before
    /// the all-purpose binding.
    pub(super) fn compute_bound_material(&mut self, prim: &sdf::Path) -> Option<sdf::Path> {
        [PURPOSE, ""]
            .into_iter()
            .find_map(|purpose| self.bound_for_purpose(prim, purpose))
    }

    fn bound_for_purpose(&mut self, prim: &sdf::Path, purpose: &str) -> Option<sdf::Path> {
        let mut winner = None;
        let mut at = Some(prim.clone());
        while let Some(path) = at {
            if path.is_abs_root() {
                break;
            }
            if let Some((material, stronger)) = self.binding_at(&path, prim, purpose)
                && (winner.is_none() || stronger)
            {
                winner = Some(material);
            }
            at = path.parent();
        }
        winner
    }

    /// The binding on `at` that applies to `queried`: the material and whether it is
    /// `strongerThanDescendants`.
    fn binding_at(
        &mut self,
        at: &sdf::Path,
        queried: &sdf::Path,
        purpose: &str,
    ) -> Option<(sdf::Path, bool)> {
        let suffix = |base: &str| match purpose {
            "" => base.to_string(),
            p => format!("{base}:{p}"),
        };
        let collection_prefix = format!("{}:", suffix("material:binding:collection"));
        let names = self.stage.prim(at.clone()).property_names().ok()?;
        for name in names
            .iter()
            .filter_map(|n| n.strip_prefix(&collection_prefix))
        {
            // A purpose-free name `material:binding:collection:NAME` must not be read as
            // the purpose `NAME`: only names without a further colon belong here.
            if name.contains(':') {
                continue;
            }
            let rel = at
                .append_property(format!("{collection_prefix}{name}"))
                .ok()?;
            let targets = self.stage.relationship(rel.clone()).targets().ok()?;
            let [collection, material] = targets.as_slice() else {
                continue;
            };
            if self.collection_includes(collection, queried) {
                return Some((material.clone(), self.stronger(&rel)));
            }
        }
        let rel = at.append_property(suffix("material:binding")).ok()?;
        let material = self
            .stage
            .relationship(rel.clone())
            .targets()
            .ok()?
            .into_iter()
            .next()?;
        Some((material, self.stronger(&rel)))
    }

    fn stronger(&self, binding: &sdf::Path) -> bool {
        self.stage
            .attribute(binding.clone())
            .get_metadata::<sdf::Value>("bindMaterialAs")
            .ok()
            .flatten()
            .as_ref()
            .and_then(as_token)
            .is_some_and(|s| s == "strongerThanDescendants")
    }

    /// Whether the collection at `collection` (`/prim.collection:name`) includes `prim`,
    /// its membership computed once per collection.
    fn collection_includes(&mut self, collection: &sdf::Path, prim: &sdf::Path) -> bool {
        let key = collection.as_str().to_string();
        if !self.collections.contains_key(&key) {
            let query = usd::is_collection_api_path(collection).and_then(|(owner, name)| {
                usd::Collection::new(owner, name)
                    .compute_membership_query(&self.stage)
                    .ok()
            });
            self.collections.insert(key.clone(), query);
        }
        self.collections[&key]
            .as_ref()
            .is_some_and(|q| q.is_path_included(prim))
    }

    /// The shader driving `material`'s surface: the universal `outputs:surface` first, then
    /// render-context terminals (`outputs:CONTEXT:surface`, sorted), each followed through
    /// NodeGraphs.
    pub(super) fn compute_surface_source(&self, material: &sdf::Path) -> Option<sdf::Path> {
        let mut terminals = vec!["outputs:surface".to_string()];
        let mut contexts: Vec<String> = self
            .stage
            .prim(material.clone())
            .property_names()
            .unwrap_or_default()
            .into_iter()
            .map(|n| n.to_string())
            .filter(|n| {
                n.strip_prefix("outputs:")
                    .and_then(|rest| rest.strip_suffix(":surface"))
                    .is_some_and(|ctx| !ctx.is_empty() && !ctx.contains(':'))
            })
            .collect();
        contexts.sort();
        terminals.extend(contexts);
        terminals
            .iter()
            .find_map(|terminal| match self.source_of(material, terminal)? {
                Source::Node { prim, .. } => Some(prim),
                Source::Value(_) => None,
            })
    }

    /// What feeds `property` of `prim`: connections are followed through NodeGraph and
    /// Material outputs and interface inputs until a shader's output or an authored value.
    /// `None` when nothing is connected and no value is authored.
    pub(super) fn source_of(&self, prim: &sdf::Path, property: &str) -> Option<Source> {
        let (mut prim, mut property) = (prim.clone(), property.to_string());
        for _ in 0..MAX_HOPS {
            let attribute = self.stage.attribute(prim.append_property(&property).ok()?);
            let Some(source) = attribute.connections().ok()?.into_iter().next() else {
                return attribute
                    .get_at::<sdf::Value>(self.time)
                    .ok()
                    .flatten()
                    .map(Source::Value);
            };
            let target = source.prim_path();
            let name = source
                .as_str()
                .rsplit_once('.')
                .map_or("", |(_, n)| n)
                .to_string();
            let kind = self.type_of(&target);
            let passes_through = matches!(kind.as_str(), "NodeGraph" | "Material")
                || (name.starts_with("inputs:") && kind != "Shader");
            if !passes_through {
                return Some(Source::Node {
                    prim: target,
                    output: name,
                });
            }
            (prim, property) = (target, name);
        }
        None
    }

    /// The shader node feeding `property` of `prim`, if any.
    pub(super) fn connected_prim(&self, prim: &sdf::Path, property: &str) -> Option<sdf::Path> {
        match self.source_of(prim, property)? {
            Source::Node { prim, .. } => Some(prim),
            Source::Value(_) => None,
        }
    }

    /// The output (`outputs:r`, …) of the shader node feeding `property` of `prim`.
    pub(super) fn connected_output(&self, prim: &sdf::Path, property: &str) -> Option<String> {
        match self.source_of(prim, property)? {
            Source::Node { output, .. } => Some(output),
            Source::Value(_) => None,
        }
    }

    /// The value feeding `property` of `prim`, read through interface inputs.
    pub(super) fn input_value(&self, prim: &sdf::Path, property: &str) -> Option<sdf::Value> {
        match self.source_of(prim, property)? {
            Source::Value(v) => Some(v),
            Source::Node { .. } => None,
        }
    }

    fn type_of(&self, prim: &sdf::Path) -> String {
        self.stage
            .prim(prim.clone())
            .type_name()
            .ok()
            .flatten()
            .map(|t| t.as_str().to_string())
            .unwrap_or_default()
    }
}

/// Collection membership queries by collection path (`None`: not a collection).
pub(super) type Collections = HashMap<String, Option<usd::MembershipQuery>>;
