//! USD asset paths through the file-access policy: an `ar::Resolver` that anchors and
//! resolves as openusd's default one does (layer-relative identifiers, `.usdz` packages),
//! but opens only regular files inside the scene's roots, refuses text layers nested
//! deeper than the parser can take, and remembers every refusal so the load can fail
//! with it rather than silently drop a layer.

use std::io;
use std::path::Path;
use std::sync::{Arc, Mutex};

use openusd::ar::{self, Asset, ResolvedPath, Resolver};

use super::mtlx_layer::{LAYER_SUFFIX, document_of, is_document, translate};
use crate::limits::memory_left;
use crate::load::access::{AccessError, AssetRoots, read_regular_file};

/// Deepest nesting of `{`, `[` and `(` accepted in a `.usda` layer. openusd's text parser
/// recurses once per level; real files stay below a few dozen, and 10,000 levels overflow
/// the stack (found by hostile testing).
pub const MAX_TEXT_NESTING: usize = 500;

/// Refusals met while the stage was composed, as messages.
pub type Refusals = Arc<Mutex<Vec<String>>>;

/// What a texture path holds in place of a UDIM tile's number (`wood.<UDIM>.png`), as
/// Blender, USD and MaterialX write it.
pub const UDIM_TOKEN: &str = "<UDIM>";

/// Warnings met while MaterialX documents were read as layers, one line each.
pub type Notes = Arc<Mutex<Vec<String>>>;

/// Missing layers a stage may name before the rest are no longer looked for: openusd
/// gathers its composition errors by comparing each new one with all before it, so its
/// time grows with the square of their number (20,000 missing sublayers took 9.4 s).
pub const MAX_MISSING_LAYERS: usize = 1000;

/// openusd's resolver behind the policy.
pub struct ConfinedResolver {
    inner: ar::DefaultResolver,
    roots: AssetRoots,
    refused: Refusals,
    /// Missing text layers past [`MAX_MISSING_LAYERS`], stood in for by empty layers.
    skipped: Skipped,
    notes: Notes,
    missing: std::sync::atomic::AtomicUsize,
}

/// The missing layers stood in for by empty ones.
pub type Skipped = Arc<Mutex<SkippedLayers>>;

/// Missing layers no longer looked for.
#[derive(Default)]
pub struct SkippedLayers {
    /// The first one named.
    pub first: Option<String>,
    /// Their paths.
    pub names: std::collections::HashSet<String>,
}

/// What an empty stand-in layer holds.
const EMPTY_LAYER: &[u8] = b"#usda 1.0\n";

impl ConfinedResolver {
    /// A resolver reading only inside `roots`; refusals are added to `refused`.
    pub fn new(
        roots: AssetRoots,
        refused: Refusals,
        skipped: Skipped,
        notes: Notes,
    ) -> ConfinedResolver {
        ConfinedResolver {
            inner: ar::DefaultResolver::new(),
            roots,
            refused,
            skipped,
            notes,
            missing: std::sync::atomic::AtomicUsize::new(0),
        }
    }

    /// Counts a missing layer; past the limit, a text layer resolves to an empty stand-in
    /// (openusd then records no error for it) and is remembered for one summary warning.
    fn missing_layer(&self, asset_path: &str) -> Option<ResolvedPath> {
        let seen = self
            .missing
            .fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let text = [".usda", ".usd"]
            .iter()
            .any(|e| asset_path.to_ascii_lowercase().ends_with(e));
        if seen < MAX_MISSING_LAYERS || !text {
            return None;
        }
        if let Ok(mut skipped) = self.skipped.lock() {
            skipped.first.get_or_insert_with(|| asset_path.to_string());
            skipped.names.insert(asset_path.to_string());
        }
        Some(ResolvedPath::new(asset_path))
    }

    fn is_stand_in(&self, name: &str) -> bool {
        self.skipped.lock().is_ok_and(|s| s.names.contains(name))
    }

    /// The file a resolved path lives in (a package's own file for `pkg.usdz[inner]`), if
    /// the policy allows it.
    fn check(&self, path: &str) -> Result<(), AccessError> {
        let file = package_file(path);
        self.roots.resolve(Path::new("/"), file).map(drop)
    }

    /// The layer a MaterialX document translates to; its warnings go to the notes.
    fn open_document(&self, document: &str) -> io::Result<Box<dyn Asset>> {
        let bytes = read_asset(document)?;
        let xml = std::str::from_utf8(&bytes).map_err(|_| {
            io::Error::new(
                io::ErrorKind::InvalidData,
                format!("{document}: not UTF-8 text"),
            )
        })?;
        let layer = translate(xml, document)
            .map_err(|why| io::Error::new(io::ErrorKind::InvalidData, why))?;
        if let Ok(mut notes) = self.notes.lock() {
            notes.extend(layer.warnings);
        }
        Ok(Box::new(io::Cursor::new(layer.text.into_bytes())))
    }

    fn refuse(&self, why: String) {
        if let Ok(mut refused) = self.refused.lock()
            && !refused.contains(&why)
        {
            refused.push(why);
        }
    }
}

impl Resolver for ConfinedResolver {
    fn create_identifier(&self, asset_path: &str, anchor: Option<&ResolvedPath>) -> String {
        self.inner.create_identifier(asset_path, anchor)
    }

    fn resolve(&self, asset_path: &str) -> Option<ResolvedPath> {
        if asset_path.is_empty() {
            return None;
        }
        // Relative identifiers (no anchor) would be searched for in the working folder.
        let anchored = Path::new(package_file(asset_path)).is_absolute();
        match self.check(asset_path) {
            // A MaterialX document is read as the layer it translates to.
            Ok(()) if anchored && is_document(asset_path) => {
                let resolved = self.inner.resolve(asset_path)?;
                Some(ResolvedPath::new(format!(
                    "{}{LAYER_SUFFIX}",
                    resolved.to_string_lossy()
                )))
            }
            Ok(()) if anchored => self.inner.resolve(asset_path),
            Ok(()) if is_layer(asset_path) => {
                self.refuse(format!(
                    "'{asset_path}' is not anchored to a layer; refused"
                ));
                None
            }
            Ok(()) => None,
            // A missing file is the composition's business (an unresolved layer).
            Err(AccessError::Missing { .. }) if anchored && is_layer(asset_path) => {
                self.missing_layer(asset_path)
            }
            // A UDIM pattern names no file itself: the loader finds its tiles.
            Err(AccessError::Missing { .. }) if anchored && asset_path.contains(UDIM_TOKEN) => {
                Some(ResolvedPath::new(asset_path))
            }
            Err(AccessError::Missing { .. }) => None,
            // A refused layer fails the load. A refused texture resolves to its path so
            // that the loader, which reads textures itself through the same policy, can
            // say why it refuses it.
            Err(why) if is_layer(asset_path) => {
                self.refuse(why.to_string());
                None
            }
            Err(_) if anchored => Some(ResolvedPath::new(asset_path)),
            Err(_) => None,
        }
    }

    fn resolve_for_new_asset(&self, _asset_path: &str) -> Option<ResolvedPath> {
        None
    }

    fn open_asset(&self, resolved: &ResolvedPath) -> io::Result<Box<dyn Asset>> {
        let name = resolved.to_string_lossy();
        if self.is_stand_in(&name) {
            return Ok(Box::new(io::Cursor::new(EMPTY_LAYER.to_vec())));
        }
        if let Err(why) = self.check(&name) {
            self.refuse(why.to_string());
            return Err(io::Error::other(why.to_string()));
        }
        if let Some(document) = document_of(&name) {
            return self.open_document(document);
        }
        let bytes = read_asset(&name)?;
        if !bytes.starts_with(b"PXR-USDC") && !bytes.starts_with(b"PK") {
            let depth = nesting_depth(&bytes);
            if depth > MAX_TEXT_NESTING {
                return Err(io::Error::new(
                    io::ErrorKind::InvalidData,
                    format!(
                        "{name}: nested {depth} levels deep, more than the {MAX_TEXT_NESTING} gridtrace reads"
                    ),
                ));
            }
        }
        Ok(Box::new(io::Cursor::new(bytes)))
    }

    fn identity(&self) -> String {
        let roots: Vec<String> = self
            .roots
            .roots()
            .iter()
            .map(|r| format!("{r:?}"))
            .collect();
        format!("gridtrace-confined{}", roots.concat())
    }
}

/// The bytes of a resolved asset: a regular file, or a member of a `.usdz` package
/// (`pkg.usdz[dir/tex.png]`, packages nested in packages included), read whole but never
/// beyond the memory budget. The caller has checked the outer file against the policy.
pub fn read_asset(resolved: &str) -> io::Result<Vec<u8>> {
    let budget = memory_left();
    let Some((package, inner)) = ar::split_package_relative_path_outer(resolved) else {
        return read_regular_file(Path::new(resolved), resolved, budget)
            .map_err(|e| io::Error::other(e.to_string()));
    };
    // Opened in place, not read whole: a package is read once per member.
    if !std::fs::metadata(&package)?.is_file() {
        return Err(io::Error::other(format!("{package}: not a regular file")));
    }
    let archive = std::fs::File::open(&package)?;
    read_member(archive, &inner, budget, 0).map_err(|e| io::Error::other(format!("{package}: {e}")))
}

/// Deepest nesting of packages inside packages read.
const MAX_PACKAGE_NESTING: usize = 8;

/// Member `inner` (itself maybe `nested.usdz[member]`) of the zip archive in `archive`.
/// A member's declared size is checked against `budget` before it is read, and the read is
/// cut at the budget whatever the declaration says (the usdz specification stores members
/// uncompressed; a compressed one could expand without bound).
fn read_member(
    archive: impl io::Read + io::Seek,
    inner: &str,
    budget: u64,
    depth: usize,
) -> io::Result<Vec<u8>> {
    use std::io::Read;
    if depth >= MAX_PACKAGE_NESTING {
        return Err(io::Error::other(format!(
            "packages nested more than {MAX_PACKAGE_NESTING} deep"
        )));
    }
    let (member, rest) = match ar::split_package_relative_path_outer(inner) {
        Some((member, rest)) => (member, Some(rest)),
        None => (inner.to_string(), None),
    };
    let mut archive = archive;
    let declared = declared_members(&mut archive);
    let mut zip = zip::ZipArchive::new(archive).map_err(|e| {
        io::Error::new(
            io::ErrorKind::InvalidData,
            format!("not a zip archive: {e}"),
        )
    })?;
    // The zip reader keeps one member per name; two members of one name leave it to the
    // reader which one is the layer, so the package is refused rather than guessed at.
    if let Some(declared) = declared.filter(|&n| n > zip.len() as u64) {
        return Err(io::Error::new(
            io::ErrorKind::InvalidData,
            format!(
                "its directory lists {declared} members but only {} distinct names: members share a name, so which one is meant is ambiguous",
                zip.len()
            ),
        ));
    }
    let entry = zip.by_name(&member).map_err(|e| match e {
        zip::result::ZipError::FileNotFound => {
            io::Error::new(io::ErrorKind::NotFound, format!("no member '{member}'"))
        }
        other => io::Error::other(format!(
            "member '{member}' cannot be read ({other}; a usdz package stores its members uncompressed)"
        )),
    })?;
    if entry.size() > budget {
        return Err(io::Error::other(format!(
            "member '{member}' declares {} bytes, more than the memory budget",
            entry.size()
        )));
    }
    let mut bytes = Vec::new();
    entry.take(budget + 1).read_to_end(&mut bytes)?;
    if bytes.len() as u64 > budget {
        return Err(io::Error::other(format!(
            "member '{member}' expands beyond the memory budget"
        )));
    }
    match rest {
        Some(rest) => read_member(io::Cursor::new(bytes), &rest, budget, depth + 1),
        None => Ok(bytes),
    }
}

/// The number of members the zip archive's end-of-central-directory record declares
/// (APPNOTE 4.3.16), or `None` when there is no such record or it defers to the Zip64 one.
fn declared_members(archive: &mut (impl io::Read + io::Seek)) -> Option<u64> {
    use std::io::SeekFrom;
    const SIGNATURE: [u8; 4] = *b"PK\x05\x06";
    // The record (22 bytes) ends the file, followed by a comment of up to 65,535 bytes.
    let end = archive.seek(SeekFrom::End(0)).ok()?;
    let start = end.saturating_sub(22 + 0xffff);
    archive.seek(SeekFrom::Start(start)).ok()?;
    let mut tail = Vec::new();
    archive.read_to_end(&mut tail).ok()?;
    archive.seek(SeekFrom::Start(0)).ok()?;
    let at = tail.windows(4).rposition(|w| w == SIGNATURE)?;
    let total = tail.get(at + 10..at + 12)?;
    match u16::from_le_bytes([total[0], total[1]]) {
        0xffff => None,
        n => Some(u64::from(n)),
    }
}

/// True for paths that name a layer (or a package of layers, or a MaterialX document read
/// as a layer) by their extension.
pub fn is_layer(path: &str) -> bool {
    let file = package_file(path).to_ascii_lowercase();
    [".usd", ".usda", ".usdc", ".usdz", ".mtlx"]
        .iter()
        .any(|e| file.ends_with(e))
}

/// The outer file of a package-relative path (`/a/b.usdz[c/d.usdc]` → `/a/b.usdz`), or the
/// path itself.
pub fn package_file(path: &str) -> &str {
    match (path.find('['), path.ends_with(']')) {
        (Some(open), true) => &path[..open],
        _ => path,
    }
}

/// Deepest nesting of brackets in USD text, outside strings and comments.
pub fn nesting_depth(text: &[u8]) -> usize {
    let (mut depth, mut deepest) = (0usize, 0usize);
    let mut i = 0;
    while i < text.len() {
        match text[i] {
            b'{' | b'[' | b'(' => {
                depth += 1;
                deepest = deepest.max(depth);
            }
            b'}' | b']' | b')' => depth = depth.saturating_sub(1),
            b'#' => {
                while i < text.len() && text[i] != b'\n' {
                    i += 1;
                }
            }
            quote @ (b'"' | b'\'') => {
                // Triple-quoted strings run to the next triple quote.
                let triple = text[i..].starts_with(&[quote; 3]);
                i += if triple { 3 } else { 1 };
                while i < text.len() {
                    if text[i] == b'\\' {
                        i += 2;
                        continue;
                    }
                    if triple && text[i..].starts_with(&[quote; 3]) {
                        i += 2;
                        break;
                    }
                    if !triple && (text[i] == quote || text[i] == b'\n') {
                        break;
                    }
                    i += 1;
                }
            }
            b'@' => {
                // Asset paths may hold brackets (`pkg.usdz[inner]`).
                let end = text[i + 1..].iter().position(|&c| c == b'@' || c == b'\n');
                i += end.map_or(text.len(), |e| e + 1);
            }
            _ => {}
        }
        i += 1;
    }
    deepest
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nesting_ignores_strings_comments_and_asset_paths() {
        assert_eq!(nesting_depth(b"def X { a = [(1, 2)] }"), 3);
        assert_eq!(
            nesting_depth(b"# {{{{\n\"{[(\" '[[' \"\"\"{\n{\"\"\" @a.usdz[b]@ {}"),
            1
        );
        assert_eq!(nesting_depth("{".repeat(10_000).as_bytes()), 10_000);
    }

    #[test]
    fn package_paths_name_their_archive() {
        assert_eq!(package_file("/a/b.usdz[c/d.usdc]"), "/a/b.usdz");
        assert_eq!(package_file("/a/b.usda"), "/a/b.usda");
    }
}
