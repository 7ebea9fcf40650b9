//! The decoders behind glTF's compression extensions on arbitrary bytes, reached the way a
//! file reaches them: the input's first byte picks a Draco primitive, a meshopt buffer view
//! (mode, filter and stride from the next bytes) or a KTX2 texture, and the rest is the
//! compressed stream inside an otherwise valid GLB. Errors and warnings are fine; panics,
//! aborts and hangs are not.
#![no_main]

use libfuzzer_sys::fuzz_target;

/// A GLB of `json` (spaces pad it) and `bin`.
fn glb(json: &str, bin: &[u8]) -> Vec<u8> {
    let mut text = json.as_bytes().to_vec();
    while !text.len().is_multiple_of(4) {
        text.push(b' ');
    }
    let mut bin = bin.to_vec();
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let mut out = Vec::new();
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&((28 + text.len() + bin.len()) as u32).to_le_bytes());
    out.extend_from_slice(&(text.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&text);
    out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(&bin);
    out
}

fn draco(stream: &[u8]) -> Vec<u8> {
    let json = format!(
        r#"{{"asset":{{"version":"2.0"}},"extensionsUsed":["KHR_draco_mesh_compression"],"extensionsRequired":["KHR_draco_mesh_compression"],
"buffers":[{{"byteLength":{n}}}],"bufferViews":[{{"buffer":0,"byteLength":{n}}}],
"accessors":[{{"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,1]}},{{"componentType":5126,"count":3,"type":"VEC3"}},{{"componentType":5125,"count":3,"type":"SCALAR"}}],
"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0,"NORMAL":1}},"indices":2,"extensions":{{"KHR_draco_mesh_compression":{{"bufferView":0,"attributes":{{"POSITION":0,"NORMAL":1}}}}}}}}]}}],
"nodes":[{{"mesh":0}}],"scenes":[{{"nodes":[0]}}]}}"#,
        n = stream.len()
    );
    glb(&json, stream)
}

fn meshopt(control: &[u8], stream: &[u8]) -> Vec<u8> {
    let mode = ["ATTRIBUTES", "TRIANGLES", "INDICES"][control[0] as usize % 3];
    let filter = ["NONE", "OCTAHEDRAL", "QUATERNION", "EXPONENTIAL", "COLOR"][control[1] as usize % 5];
    let stride = match mode {
        "ATTRIBUTES" => 4 * (1 + control[2] as usize % 4),
        _ => 2 + 2 * (control[2] as usize % 2),
    };
    let count = 3 * (1 + control[3] as usize % 16);
    let length = count * stride;
    let json = format!(
        r#"{{"asset":{{"version":"2.0"}},"extensionsUsed":["EXT_meshopt_compression"],"extensionsRequired":["EXT_meshopt_compression"],
"buffers":[{{"byteLength":{n}}},{{"byteLength":{length},"extensions":{{"EXT_meshopt_compression":{{"fallback":true}}}}}}],
"bufferViews":[{{"buffer":1,"byteLength":{length},"byteStride":{attribute_stride},"extensions":{{"EXT_meshopt_compression":{{"buffer":0,"byteLength":{n},"byteStride":{stride},"count":{count},"mode":"{mode}","filter":"{filter}"}}}}}}],
"accessors":[{{"bufferView":0,"componentType":5126,"count":{vertices},"type":"VEC3","min":[0,0,0],"max":[1,1,1]}}],
"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}}}}]}}],"nodes":[{{"mesh":0}}],"scenes":[{{"nodes":[0]}}]}}"#,
        n = stream.len(),
        attribute_stride = stride.max(12),
        vertices = if stride >= 12 { count } else { 0 },
    );
    glb(&json, stream)
}

fn ktx2(image: &[u8]) -> Vec<u8> {
    let mut bin = Vec::new();
    for p in [[0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]] {
        p.iter().for_each(|c| bin.extend_from_slice(&c.to_le_bytes()));
    }
    for uv in [[0f32, 0.0], [1.0, 0.0], [0.0, 1.0]] {
        uv.iter().for_each(|c| bin.extend_from_slice(&c.to_le_bytes()));
    }
    bin.extend_from_slice(image);
    let json = format!(
        r#"{{"asset":{{"version":"2.0"}},"extensionsUsed":["KHR_texture_basisu"],"extensionsRequired":["KHR_texture_basisu"],
"buffers":[{{"byteLength":{total}}}],"bufferViews":[{{"buffer":0,"byteLength":36}},{{"buffer":0,"byteOffset":36,"byteLength":24}},{{"buffer":0,"byteOffset":60,"byteLength":{n}}}],
"accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}},{{"bufferView":1,"componentType":5126,"count":3,"type":"VEC2"}}],
"images":[{{"bufferView":2,"mimeType":"image/ktx2"}}],"textures":[{{"extensions":{{"KHR_texture_basisu":{{"source":0}}}}}}],
"materials":[{{"pbrMetallicRoughness":{{"baseColorTexture":{{"index":0}}}}}}],
"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0,"TEXCOORD_0":1}},"material":0}}]}}],"nodes":[{{"mesh":0}}],"scenes":[{{"nodes":[0]}}]}}"#,
        total = 60 + image.len(),
        n = image.len()
    );
    glb(&json, &bin)
}

fuzz_target!(|data: &[u8]| {
    // A budget the fuzzer's 2 GB memory limit can hold: a few bytes may declare gigabytes.
    gridtrace::limits::set_memory_budget(1 << 30);
    let Some((&choice, rest)) = data.split_first() else {
        return;
    };
    let file = match choice % 3 {
        0 => draco(rest),
        1 if rest.len() >= 4 => meshopt(&rest[..4], &rest[4..]),
        1 => return,
        _ => ktx2(rest),
    };
    let _ = gridtrace::load::gltf::load_bytes(&file, std::path::Path::new("fuzz.glb"));
});
