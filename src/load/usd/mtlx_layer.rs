//! MaterialX documents (`.mtlx`) as USD layers, laid out as USD's own MaterialX file format
//! (usdMtlx) lays them out: each `surfacematerial` becomes a Material at
//! `/MaterialX/Materials/NAME` whose `outputs:mtlx:surface` connects to its surface shader,
//! with the nodes and node graphs it uses copied beneath it, so that a reference to the
//! material carries its whole network. Every node is a `Shader` whose `info:id` is its
//! node definition (`ND_image_color3`). The stage then composes the layer like any other
//! and the material reader sees one kind of network whatever wrote it.
//! MaterialX Specification v1.39: "MaterialX Documents", "Nodes", "Node Graphs",
//! "Material Nodes", "Filename Substitutions" (`fileprefix`), "Color Spaces".

use std::collections::{HashMap, HashSet, VecDeque};
use std::fmt::Write as _;

/// What a resolved `.mtlx` path is given as a suffix, so that the stage reads it as a text
/// layer (its format is chosen by extension). The package syntax keeps the document's own
/// file first, where the file-access policy looks for it.
pub const LAYER_SUFFIX: &str = "[materialx.usda]";

/// Most node copies one document may produce (nodes × the materials using them): a
/// document of a few kilobytes could otherwise name a graph of thousands of nodes from
/// thousands of materials.
const MAX_NODE_COPIES: usize = 200_000;

/// Most XML nodes parsed from one document.
const MAX_XML_NODES: u32 = 4_000_000;

/// A document translated: the layer's text and what was left out of it.
pub struct Translated {
    /// A `.usda` layer.
    pub text: String,
    /// One line each, naming the document.
    pub warnings: Vec<String>,
}

/// The path of the document a translated layer was made from, if `resolved` names one.
pub fn document_of(resolved: &str) -> Option<&str> {
    resolved.strip_suffix(LAYER_SUFFIX)
}

/// True for asset paths naming a MaterialX document.
pub fn is_document(path: &str) -> bool {
    super::resolver::package_file(path)
        .to_ascii_lowercase()
        .ends_with(".mtlx")
}

/// The layer for the document `xml`, read from `document` (its resolved path, which
/// anchors the document's file names and names it in messages).
pub fn translate(xml: &str, document: &str) -> Result<Translated, String> {
    let options = roxmltree::ParsingOptions {
        allow_dtd: false,
        nodes_limit: MAX_XML_NODES,
        ..roxmltree::ParsingOptions::default()
    };
    let parsed = roxmltree::Document::parse_with_options(xml, options)
        .map_err(|e| format!("{document}: not a MaterialX document: {e}"))?;
    let root = parsed.root_element();
    if root.tag_name().name() != "materialx" {
        return Err(format!(
            "{document}: not a MaterialX document (its root element is <{}>, not <materialx>)",
            root.tag_name().name()
        ));
    }
    let mut writer = Writer {
        document,
        top: HashMap::new(),
        graphs: HashMap::new(),
        text: String::new(),
        warnings: Vec::new(),
        copies: 0,
    };
    for element in root.children().filter(|n| n.is_element()) {
        let name = element.attribute("name").unwrap_or_default();
        match element.tag_name().name() {
            "nodegraph" if element.attribute("nodedef").is_none() => {
                writer.graphs.insert(name, element);
            }
            tag if IGNORED.contains(&tag) || element.attribute("nodedef").is_some() && tag == "nodegraph" => {}
            "include" => writer.warn(format!(
                "includes another document ('{}'), which is not read",
                element.attribute("href").unwrap_or_default()
            )),
            "material" => writer.warn(format!(
                "material '{name}' is a MaterialX 1.37 <material>, which is not read; save the document as 1.38 or later"
            )),
            _ => {
                writer.top.insert(name, element);
            }
        }
    }
    writer.text.push_str(
        "#usda 1.0\n(\n    defaultPrim = \"MaterialX\"\n)\n\ndef Scope \"MaterialX\"\n{\n    def Scope \"Materials\"\n    {\n",
    );
    let mut materials: Vec<_> = writer
        .top
        .values()
        .copied()
        .filter(|e| e.tag_name().name() == "surfacematerial")
        .collect();
    materials.sort_by_key(|e| e.range().start);
    if materials.is_empty() {
        writer.warn("has no surfacematerial".into());
    }
    for material in materials {
        writer.material(material)?;
    }
    writer.text.push_str("    }\n}\n");
    Ok(Translated {
        text: writer.text,
        warnings: writer.warnings,
    })
}

/// Top-level elements that are not nodes and hold nothing a material needs.
const IGNORED: &[&str] = &[
    "nodedef",
    "implementation",
    "typedef",
    "unittypedef",
    "unitdef",
    "look",
    "lookgroup",
    "materialassign",
    "collection",
    "geominfo",
    "propertyset",
    "propertysetassign",
    "variantset",
    "variantassign",
    "visibility",
    "backdrop",
    "token",
    "input",
    "output",
];

type Element<'a, 'input> = roxmltree::Node<'a, 'input>;

struct Writer<'a, 'input> {
    document: &'a str,
    /// Top-level nodes by name.
    top: HashMap<&'a str, Element<'a, 'input>>,
    /// Node graphs by name.
    graphs: HashMap<&'a str, Element<'a, 'input>>,
    text: String,
    warnings: Vec<String>,
    copies: usize,
}

impl<'a, 'input> Writer<'a, 'input> {
    fn warn(&mut self, what: String) {
        self.warnings.push(format!("{}: {what}", self.document));
    }

    /// One Material prim with its surface shader and everything that feeds it.
    fn material(&mut self, material: Element<'a, 'input>) -> Result<(), String> {
        let name = prim_name(material.attribute("name").unwrap_or("material"));
        let path = format!("/MaterialX/Materials/{name}");
        let surface = inputs(material).find(|i| i.attribute("name") == Some("surfaceshader"));
        let Some(shader) = surface.and_then(|s| s.attribute("nodename")) else {
            self.warn(format!(
                "material '{name}' has no surfaceshader input connected to a node; skipped"
            ));
            return Ok(());
        };
        let Some(&shader_node) = self.top.get(shader) else {
            self.warn(format!(
                "material '{name}' names a surface shader '{shader}' the document does not have; skipped"
            ));
            return Ok(());
        };
        let _ = writeln!(self.text, "        def Material \"{name}\"\n        {{");
        let _ = writeln!(
            self.text,
            "            token outputs:mtlx:surface.connect = <{path}/{}.outputs:surface>",
            prim_name(shader)
        );
        // The top-level nodes and graphs the shader reaches, each copied once.
        let (mut nodes, mut graphs) = (vec![shader_node], Vec::new());
        let mut seen: HashSet<&str> = HashSet::from([shader]);
        let mut queue = VecDeque::from([shader_node]);
        while let Some(node) = queue.pop_front() {
            for input in inputs(node) {
                if let Some(n) = input.attribute("nodename")
                    && let Some(&next) = self.top.get(n)
                    && seen.insert(n)
                {
                    nodes.push(next);
                    queue.push_back(next);
                }
                if let Some(g) = input.attribute("nodegraph")
                    && let Some(&graph) = self.graphs.get(g)
                    && seen.insert(g)
                {
                    graphs.push(graph);
                }
            }
        }
        for node in nodes {
            self.node(node, &path, 3)?;
        }
        for graph in graphs {
            self.graph(graph, &path)?;
        }
        self.text.push_str("        }\n");
        Ok(())
    }

    /// A NodeGraph prim under `parent`: its interface inputs, its outputs and its nodes.
    fn graph(&mut self, graph: Element<'a, 'input>, parent: &str) -> Result<(), String> {
        let name = prim_name(graph.attribute("name").unwrap_or("graph"));
        let path = format!("{parent}/{name}");
        let _ = writeln!(
            self.text,
            "            def NodeGraph \"{name}\"\n            {{"
        );
        for child in graph.children().filter(|c| c.is_element()) {
            match child.tag_name().name() {
                "input" => self.input(child, &path, &path, 4),
                "output" => {
                    let usd = usd_type(child.attribute("type").unwrap_or_default());
                    let out = prim_name(child.attribute("name").unwrap_or("out"));
                    match child.attribute("nodename") {
                        Some(n) => {
                            let port = child.attribute("output").unwrap_or("out");
                            let _ = writeln!(
                                self.text,
                                "                {} outputs:{out}.connect = <{path}/{}.outputs:{}>",
                                usd.unwrap_or("token"),
                                prim_name(n),
                                prim_name(port)
                            );
                        }
                        None => {
                            let _ = writeln!(
                                self.text,
                                "                {} outputs:{out}",
                                usd.unwrap_or("token")
                            );
                        }
                    }
                }
                _ => self.node(child, &path, 4)?,
            }
        }
        self.text.push_str("            }\n");
        Ok(())
    }

    /// A node as a Shader prim under `parent` (a Material or a NodeGraph), `depth` levels in.
    fn node(
        &mut self,
        node: Element<'a, 'input>,
        parent: &str,
        depth: usize,
    ) -> Result<(), String> {
        self.copies += 1;
        if self.copies > MAX_NODE_COPIES {
            return Err(format!(
                "{}: its materials use more than {MAX_NODE_COPIES} nodes",
                self.document
            ));
        }
        let indent = "    ".repeat(depth);
        let name = prim_name(node.attribute("name").unwrap_or("node"));
        let category = node.tag_name().name();
        let kind = node.attribute("type").unwrap_or_default();
        let id = match node.attribute("nodedef") {
            Some(def) => def.to_string(),
            None if kind == "surfaceshader" => format!("ND_{category}_surfaceshader"),
            None if category == "convert" => {
                let from = inputs(node)
                    .find(|i| i.attribute("name") == Some("in"))
                    .and_then(|i| i.attribute("type"))
                    .unwrap_or_default();
                format!("ND_convert_{from}_{kind}")
            }
            None => format!("ND_{category}_{kind}"),
        };
        let _ = writeln!(self.text, "{indent}def Shader \"{name}\"\n{indent}{{");
        let _ = writeln!(
            self.text,
            "{indent}    uniform token info:id = \"{}\"",
            escape(&id)
        );
        let scope = parent.to_string();
        for input in inputs(node) {
            self.input(input, &scope, parent, depth + 1);
        }
        match (kind, usd_type(kind)) {
            ("surfaceshader", _) => {
                let _ = writeln!(self.text, "{indent}    token outputs:surface");
            }
            (_, Some(usd)) => {
                let _ = writeln!(self.text, "{indent}    {usd} outputs:out");
            }
            _ => {}
        }
        let _ = writeln!(self.text, "{indent}}}");
        Ok(())
    }

    /// One input: a value, or a connection to a node beside it (`nodename`), to a graph's
    /// output (`nodegraph`, top level only) or to its graph's interface (`interfacename`).
    /// `siblings` is where named nodes live, `graph` the prim whose interface it may read.
    fn input(&mut self, input: Element<'a, 'input>, siblings: &str, graph: &str, depth: usize) {
        let indent = "    ".repeat(depth);
        let name = prim_name(input.attribute("name").unwrap_or_default());
        let kind = input.attribute("type").unwrap_or_default();
        let Some(usd) = usd_type(kind) else {
            self.warn(format!("input '{name}' of type '{kind}' is not read"));
            return;
        };
        let port = |e: Element| prim_name(e.attribute("output").unwrap_or("out"));
        let source = if let Some(node) = input.attribute("nodename") {
            let surface = self
                .top
                .get(node)
                .is_some_and(|n| n.attribute("type") == Some("surfaceshader"));
            let port = if surface {
                "surface".to_string()
            } else {
                port(input)
            };
            Some(format!("{siblings}/{}.outputs:{port}", prim_name(node)))
        } else if let Some(g) = input.attribute("nodegraph") {
            let output = input
                .attribute("output")
                .map(prim_name)
                .or_else(|| self.only_output(g))
                .unwrap_or_else(|| "out".into());
            Some(format!("{siblings}/{}.outputs:{output}", prim_name(g)))
        } else {
            input
                .attribute("interfacename")
                .map(|i| format!("{graph}.inputs:{}", prim_name(i)))
        };
        if let Some(source) = source {
            let _ = writeln!(
                self.text,
                "{indent}{usd} inputs:{name}.connect = <{source}>"
            );
            return;
        }
        let Some(raw) = input.attribute("value") else {
            return;
        };
        let space = colour_space(input);
        let value = if kind == "filename" {
            self.file_value(input, raw)
        } else {
            match usd_value(kind, raw, space.as_deref()) {
                Ok(v) => Some(v),
                Err(why) => {
                    self.warn(format!("input '{name}': {why}; left unset"));
                    None
                }
            }
        };
        let Some(value) = value else { return };
        match (kind, space) {
            ("filename", Some(space)) => {
                let _ = writeln!(
                    self.text,
                    "{indent}{usd} inputs:{name} = {value} (\n{indent}    colorSpace = \"{}\"\n{indent})",
                    escape(&space)
                );
            }
            _ => {
                let _ = writeln!(self.text, "{indent}{usd} inputs:{name} = {value}");
            }
        }
    }

    /// The name of a graph's only output, the one a `nodegraph` connection may leave unnamed.
    fn only_output(&self, graph: &str) -> Option<String> {
        let mut outputs = self
            .graphs
            .get(graph)?
            .children()
            .filter(|c| c.tag_name().name() == "output");
        let first = outputs.next()?;
        outputs
            .next()
            .is_none()
            .then(|| prim_name(first.attribute("name").unwrap_or("out")))
    }

    /// A file name as an absolute asset path: the nearest `fileprefix` in scope, then
    /// anchored at the document's folder (inside its package, if it is in one).
    fn file_value(&mut self, input: Element, raw: &str) -> Option<String> {
        if raw.is_empty() {
            return None;
        }
        let prefix = input
            .ancestors()
            .find_map(|e| e.attribute("fileprefix"))
            .unwrap_or_default();
        let file = format!("{prefix}{raw}");
        if file.contains('@') || file.chars().any(char::is_control) || file.contains("://") {
            self.warn(format!(
                "file name '{file}' cannot be read as a path; left unset"
            ));
            return None;
        }
        Some(format!("@{}@", anchor(self.document, &file)))
    }
}

/// The `<input>` children of an element.
fn inputs<'a, 'input>(element: Element<'a, 'input>) -> impl Iterator<Item = Element<'a, 'input>> {
    element
        .children()
        .filter(|c| c.is_element() && c.tag_name().name() == "input")
}

/// The colour space an input's value is in: its own `colorspace` or the nearest one in scope.
fn colour_space(input: Element) -> Option<String> {
    input
        .ancestors()
        .find_map(|e| e.attribute("colorspace"))
        .filter(|s| !s.is_empty())
        .map(str::to_string)
}

/// A name as a USD prim or property name: letters, digits and underscores, not starting
/// with a digit.
fn prim_name(name: &str) -> String {
    let mut out: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect();
    if out.is_empty() || out.starts_with(|c: char| c.is_ascii_digit()) {
        out.insert(0, '_');
    }
    out
}

/// The USD value type of a MaterialX type, for the types a material network uses.
fn usd_type(kind: &str) -> Option<&'static str> {
    Some(match kind {
        "float" => "float",
        "integer" => "int",
        "boolean" => "bool",
        "color3" => "color3f",
        "color4" => "color4f",
        "vector2" => "float2",
        "vector3" => "float3",
        "vector4" => "float4",
        "string" => "string",
        "filename" => "asset",
        "surfaceshader" | "displacementshader" | "volumeshader" | "material" | "BSDF" | "EDF"
        | "VDF" => "token",
        _ => return None,
    })
}

/// A MaterialX value string (`"0.8, 0.8, 0.8"`) as USD text, checked and reformatted so
/// nothing but numbers reaches the layer. Colours in `srgb_texture` are decoded to linear
/// (the working space); other non-linear spaces are kept as written.
fn usd_value(kind: &str, raw: &str, space: Option<&str>) -> Result<String, String> {
    let numbers = |count: usize| -> Result<Vec<f32>, String> {
        let values: Vec<f32> = raw
            .split(',')
            .map(|s| s.trim().parse::<f32>())
            .collect::<Result<_, _>>()
            .map_err(|_| format!("'{raw}' is not a {kind}"))?;
        if values.len() != count || values.iter().any(|v| !v.is_finite()) {
            return Err(format!("'{raw}' is not a {kind}"));
        }
        Ok(values)
    };
    let tuple = |v: Vec<f32>| {
        let parts: Vec<String> = v.iter().map(|x| format!("{x:?}")).collect();
        format!("({})", parts.join(", "))
    };
    let srgb = space == Some("srgb_texture");
    Ok(match kind {
        "float" => format!("{:?}", numbers(1)?[0]),
        "integer" => raw
            .trim()
            .parse::<i32>()
            .map_err(|_| format!("'{raw}' is not an integer"))?
            .to_string(),
        "boolean" => match raw.trim() {
            "true" => "true".into(),
            "false" => "false".into(),
            _ => return Err(format!("'{raw}' is not a boolean")),
        },
        "color3" | "color4" => {
            let mut v = numbers(if kind == "color3" { 3 } else { 4 })?;
            if srgb {
                for c in v.iter_mut().take(3) {
                    *c = srgb_to_linear(*c);
                }
            }
            tuple(v)
        }
        "vector2" => tuple(numbers(2)?),
        "vector3" => tuple(numbers(3)?),
        "vector4" => tuple(numbers(4)?),
        "string" => format!("\"{}\"", escape(raw)),
        _ => return Err(format!("values of type '{kind}' are not read")),
    })
}

/// The sRGB transfer function's inverse (IEC 61966-2-1).
fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// A string as the inside of a double-quoted USD string.
fn escape(s: &str) -> String {
    s.chars()
        .flat_map(|c| match c {
            '"' => vec!['\\', '"'],
            '\\' => vec!['\\', '\\'],
            c if c.is_control() => vec![' '],
            c => vec![c],
        })
        .collect()
}

/// `file` anchored at the folder of `document`; a document inside a package
/// (`pkg.usdz[dir/doc.mtlx]`) anchors inside the package. `.` and `..` are removed.
fn anchor(document: &str, file: &str) -> String {
    let (package, inner) = match (document.find('['), document.ends_with(']')) {
        (Some(open), true) => (
            Some(&document[..open]),
            &document[open + 1..document.len() - 1],
        ),
        _ => (None, document),
    };
    let joined = if file.starts_with('/') {
        file.to_string()
    } else {
        let folder = inner.rsplit_once('/').map_or("", |(f, _)| f);
        format!("{folder}/{file}")
    };
    let mut parts: Vec<&str> = Vec::new();
    for part in joined.split('/') {
        match part {
            "" | "." => {}
            ".." => {
                parts.pop();
            }
            p => parts.push(p),
        }
    }
    let absolute = package.is_none() || inner.starts_with('/');
    let path = format!("{}{}", if absolute { "/" } else { "" }, parts.join("/"));
    match package {
        Some(p) if !file.starts_with('/') => format!("{p}[{path}]"),
        _ => path,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn file_names_anchor_at_the_document_and_inside_its_package() {
        assert_eq!(anchor("/a/b/doc.mtlx", "t/x.png"), "/a/b/t/x.png");
        assert_eq!(anchor("/a/b/doc.mtlx", "../x.png"), "/a/x.png");
        assert_eq!(anchor("/a/b/doc.mtlx", "/c/x.png"), "/c/x.png");
        assert_eq!(
            anchor("/p.usdz[m/doc.mtlx]", "t/x.png"),
            "/p.usdz[m/t/x.png]"
        );
    }

    #[test]
    fn values_are_checked_and_srgb_colours_decoded() {
        assert_eq!(
            usd_value("color3", "1, 0.5,0", None).unwrap(),
            "(1.0, 0.5, 0.0)"
        );
        assert!(usd_value("color3", "1, 0.5", None).is_err());
        assert!(usd_value("float", "1) ( x", None).is_err());
        assert!(usd_value("float", "nan", None).is_err());
        let decoded = usd_value("color3", "0.5, 0.5, 0.5", Some("srgb_texture")).unwrap();
        assert!(decoded.starts_with("(0.2140"), "{decoded}");
        assert_eq!(usd_value("string", "a\"b", None).unwrap(), "\"a\\\"b\"");
    }

    #[test]
    fn names_become_prim_names() {
        assert_eq!(prim_name("SR_gold"), "SR_gold");
        assert_eq!(prim_name("3 dots.x"), "_3_dots_x");
    }
}
