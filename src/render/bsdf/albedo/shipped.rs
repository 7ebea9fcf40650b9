//! The albedo tables as shipped in the binary: `albedo_tables.bin`, the output of
//! [`super::integrate`] in little-endian `f32`s after a header that names the grid sizes.
//! Order: the Schlick split-sum pairs, the white averages, the sheen albedos, the glass
//! pairs, the Fresnel averages, each in the layout its table keeps in memory.
//!
//! To write it again after changing a lobe or a grid:
//! `GRIDTRACE_WRITE_ALBEDO_TABLES=1 cargo test --lib shipped_tables`.

use glam::Vec2;

use super::{AlbedoTables, GLASS_N, GlassTable, N};

/// What the file starts with, before the two grid sizes (`u32` each).
const MAGIC: &[u8; 8] = b"gtalbedo";

const SHIPPED: &[u8] = include_bytes!("albedo_tables.bin");

/// Numbers in the file after its header: 2N² + N + N² + 2·2G³ + G.
const VALUES: usize = 3 * N * N + N + 4 * GLASS_N * GLASS_N * GLASS_N + GLASS_N;

/// The shipped tables. A file that does not match the grids compiled in is a build
/// defect, which the test below catches before it ships.
pub fn decode() -> (AlbedoTables, GlassTable) {
    decode_bytes(SHIPPED).expect("albedo_tables.bin does not match the table grids")
}

fn decode_bytes(bytes: &[u8]) -> Option<(AlbedoTables, GlassTable)> {
    let body = bytes.strip_prefix(MAGIC.as_slice())?;
    let (sizes, body) = body.split_at_checked(8)?;
    let size = |k: usize| u32::from_le_bytes(sizes[4 * k..4 * k + 4].try_into().unwrap());
    if (size(0), size(1)) != (N as u32, GLASS_N as u32) || body.len() != 4 * VALUES {
        return None;
    }
    let mut numbers = body
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes(b.try_into().unwrap()));
    let mut floats = |n: usize| numbers.by_ref().take(n).collect::<Vec<f32>>();
    let pairs = |v: Vec<f32>| v.chunks_exact(2).map(Vec2::from_slice).collect::<Vec<_>>();
    let schlick = pairs(floats(2 * N * N));
    let white_average = floats(N);
    let sheen = floats(N * N);
    let glass = pairs(floats(4 * GLASS_N * GLASS_N * GLASS_N));
    let fresnel_average = floats(GLASS_N);
    Some((
        AlbedoTables {
            schlick,
            white_average,
            sheen,
        },
        GlassTable {
            values: glass,
            fresnel_average,
        },
    ))
}

#[cfg(test)]
fn encode(tables: &AlbedoTables, glass: &GlassTable) -> Vec<u8> {
    let mut bytes = MAGIC.to_vec();
    bytes.extend((N as u32).to_le_bytes());
    bytes.extend((GLASS_N as u32).to_le_bytes());
    let pairs = |v: &[Vec2]| v.iter().flat_map(|p| p.to_array()).collect::<Vec<f32>>();
    for part in [
        pairs(&tables.schlick),
        tables.white_average.clone(),
        tables.sheen.clone(),
        pairs(&glass.values),
        glass.fresnel_average.clone(),
    ] {
        bytes.extend(part.iter().flat_map(|x| x.to_le_bytes()));
    }
    bytes
}

#[cfg(test)]
mod tests {
    use super::super::integrate;
    use super::*;

    /// The shipped tables are what the lobes integrate to today. Integration repeats the
    /// same `f32` operations, so they agree to the bit on the machine that wrote them; the
    /// limit leaves room for a maths library that rounds its last bit otherwise.
    #[test]
    fn shipped_tables_are_the_integrated_tables() {
        let (albedo, glass) = (integrate::albedo_tables(), integrate::glass_table());
        let fresh = encode(&albedo, &glass);
        if std::env::var_os("GRIDTRACE_WRITE_ALBEDO_TABLES").is_some() {
            let path = concat!(
                env!("CARGO_MANIFEST_DIR"),
                "/src/render/bsdf/albedo/albedo_tables.bin"
            );
            std::fs::write(path, &fresh).unwrap();
        }
        let (shipped_albedo, shipped_glass) = decode();
        let shipped = encode(&shipped_albedo, &shipped_glass);
        assert_eq!(shipped.len(), fresh.len());
        let numbers = |b: &[u8]| {
            b[16..]
                .chunks_exact(4)
                .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
                .collect::<Vec<_>>()
        };
        let worst = numbers(&shipped)
            .iter()
            .zip(numbers(&fresh))
            .map(|(a, b)| (a - b).abs())
            .fold(0.0f32, f32::max);
        assert!(
            worst < 1e-5,
            "the shipped albedo tables differ from the lobes' by {worst}: write them again \
             with GRIDTRACE_WRITE_ALBEDO_TABLES=1 cargo test --lib shipped_tables"
        );
    }

    #[test]
    fn a_file_of_other_grids_is_refused() {
        let (albedo, glass) = decode();
        let mut bytes = encode(&albedo, &glass);
        assert!(decode_bytes(&bytes).is_some());
        bytes[8] = 16;
        assert!(decode_bytes(&bytes).is_none());
        assert!(decode_bytes(&bytes[..100]).is_none());
    }
}
