//! Embree 4 through its C API (`embree4-sys`). The `embree4-rs` wrapper keeps the scene
//! handle private and checks the device error after every ray, so the raw calls are used.

use std::ptr::{null, null_mut};
use std::sync::atomic::{AtomicIsize, Ordering};

use embree4_sys::*;
use gridtrace::accel::Ray;

use super::Mesh;

/// An `RTCRayHit` with room behind it. The bindings come from Embree 4.2 headers, whose
/// `RTCHit` ends at `instID`; the 4.4 library (built with instance arrays) also writes
/// `instPrimID` after it, 4 bytes past the 4.2 struct. Without this padding that write
/// lands on whatever the stack holds next: it corrupted neighbouring variables here and
/// is a likely cause of the crashes seen when calling Embree from many threads.
#[repr(C, align(16))]
struct PaddedRayHit {
    rayhit: RTCRayHit,
    _room: [u32; 8],
}

/// Bytes Embree holds, from its memory-monitor callback.
static EMBREE_BYTES: AtomicIsize = AtomicIsize::new(0);

unsafe extern "C" fn count_memory(
    _user: *mut std::os::raw::c_void,
    bytes: isize,
    _post: bool,
) -> bool {
    EMBREE_BYTES.fetch_add(bytes, Ordering::Relaxed);
    true
}

/// Gives `geometry` a new Embree-owned buffer holding a copy of `items` (12-byte items).
///
/// # Safety
/// `geometry` must be a live geometry handle; `T` must be 12 bytes matching `format`.
unsafe fn copy_into_new_buffer<T: Copy>(
    geometry: RTCGeometry,
    kind: RTCBufferType,
    format: RTCFormat,
    items: &[T],
) {
    assert_eq!(std::mem::size_of::<T>(), 12);
    // SAFETY: Embree allocates room for `items.len()` items of 12 bytes (plus its own padding).
    unsafe {
        let buffer = rtcSetNewGeometryBuffer(geometry, kind, 0, format, 12, items.len()) as *mut T;
        std::ptr::copy_nonoverlapping(items.as_ptr(), buffer, items.len());
    }
}

/// A committed Embree scene holding one triangle mesh.
pub struct Embree {
    device: RTCDevice,
    scene: RTCScene,
    /// Bytes the device allocated while building this scene.
    pub bytes: usize,
}

// SAFETY: Embree documents committed scenes as safe to query from many threads at once;
// nothing mutates the scene after `build` returns, and `Drop` needs `&mut self`.
unsafe impl Sync for Embree {}
unsafe impl Send for Embree {}

impl Embree {
    pub fn build(mesh: &Mesh) -> Embree {
        // SAFETY: plain Embree API use: the buffers returned by rtcSetNewGeometryBuffer are
        // owned by the geometry and sized for exactly the items written into them.
        unsafe {
            let device = rtcNewDevice(null());
            assert!(!device.is_null(), "rtcNewDevice failed");
            rtcSetDeviceMemoryMonitorFunction(device, Some(count_memory), null_mut());
            let before = EMBREE_BYTES.load(Ordering::Relaxed);
            let scene = rtcNewScene(device);
            let geometry = rtcNewGeometry(device, RTCGeometryType::TRIANGLE);
            let vertices: Vec<[f32; 3]> = mesh.positions.iter().map(|p| p.to_array()).collect();
            copy_into_new_buffer(
                geometry,
                RTCBufferType::VERTEX,
                RTCFormat::FLOAT3,
                &vertices,
            );
            copy_into_new_buffer(
                geometry,
                RTCBufferType::INDEX,
                RTCFormat::UINT3,
                &mesh.indices,
            );
            rtcCommitGeometry(geometry);
            rtcAttachGeometry(scene, geometry);
            rtcReleaseGeometry(geometry);
            rtcCommitScene(scene);
            assert_eq!(
                rtcGetDeviceError(device),
                RTCError::NONE,
                "Embree build failed"
            );
            let bytes = (EMBREE_BYTES.load(Ordering::Relaxed) - before).max(0) as usize;
            Embree {
                device,
                scene,
                bytes,
            }
        }
    }

    fn rtc_ray(ray: &Ray) -> RTCRay {
        RTCRay {
            org_x: ray.origin.x,
            org_y: ray.origin.y,
            org_z: ray.origin.z,
            tnear: ray.t_min,
            dir_x: ray.direction.x,
            dir_y: ray.direction.y,
            dir_z: ray.direction.z,
            time: 0.0,
            tfar: ray.t_max,
            mask: u32::MAX,
            id: 0,
            flags: 0,
        }
    }

    /// Writes `ray`'s origin and `t_min`, then its direction and a time of 0, into `r` as
    /// Embree reads them: each four as one 16-byte store. Embree loads each of the two as
    /// one 16-byte vector; written a field at a time (as [`Embree::rtc_ray`] alone writes
    /// them), such a load spans four stores still in flight, cannot take its data from them
    /// and waits until they reach the cache (a failed store-to-load forward): 16–19 ns of
    /// each query on the dragons, 8–19 % of Embree's time (measured at
    /// f44f9f7). The grid reads the benchmark's rays from memory, so this keeps the
    /// comparison level. Called just before the query, so these are the last stores to
    /// those bytes.
    #[inline(always)]
    fn store_origin_and_direction(r: &mut RTCRay, ray: &Ray) {
        #[cfg(target_arch = "x86_64")]
        {
            use std::arch::x86_64::{_mm_setr_ps, _mm_storeu_ps};
            let (o, d) = (ray.origin, ray.direction);
            // SAFETY: `org_x, org_y, org_z, tnear` and `dir_x, dir_y, dir_z, time` are four
            // consecutive `f32`s each in the `repr(C)` `RTCRay`, so each 16-byte store
            // writes exactly those fields of `r`.
            unsafe {
                _mm_storeu_ps(&mut r.org_x, _mm_setr_ps(o.x, o.y, o.z, ray.t_min));
                _mm_storeu_ps(&mut r.dir_x, _mm_setr_ps(d.x, d.y, d.z, 0.0));
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        let _ = (r, ray);
    }

    /// Closest hit (`rtcIntersect1`): (t, triangle index).
    pub fn intersect(&self, ray: &Ray) -> Option<(f32, u32)> {
        let mut padded = PaddedRayHit {
            rayhit: RTCRayHit {
                ray: Self::rtc_ray(ray),
                hit: RTCHit {
                    Ng_x: 0.0,
                    Ng_y: 0.0,
                    Ng_z: 0.0,
                    u: 0.0,
                    v: 0.0,
                    primID: u32::MAX,
                    geomID: u32::MAX,
                    instID: [u32::MAX],
                },
            },
            _room: [u32::MAX; 8],
        };
        Self::store_origin_and_direction(&mut padded.rayhit.ray, ray);
        // SAFETY: the scene is committed, and `padded` is exclusively borrowed and large
        // enough for the 4.4 library's `RTCRayHit` (see `PaddedRayHit`).
        unsafe { rtcIntersect1(self.scene, &mut padded.rayhit, null_mut()) };
        let rayhit = &padded.rayhit;
        (rayhit.hit.geomID != u32::MAX).then_some((rayhit.ray.tfar, rayhit.hit.primID))
    }

    /// Any hit (`rtcOccluded1`).
    pub fn occluded(&self, ray: &Ray) -> bool {
        let mut r = Self::rtc_ray(ray);
        Self::store_origin_and_direction(&mut r, ray);
        // SAFETY: as in `intersect`. Embree sets tfar to −∞ when the ray is occluded.
        unsafe { rtcOccluded1(self.scene, &mut r, null_mut()) };
        r.tfar == f32::NEG_INFINITY
    }
}

/// An `RTCRayHitN` with room behind it for the 4.4 library's `instPrimID` lanes (see
/// [`PaddedRayHit`]).
#[repr(C, align(64))]
struct PaddedRayHitN<T> {
    rayhit: T,
    _room: [u32; 32],
}

/// Embree's packet query of `$lanes` rays (`rtcIntersect8`, `rtcIntersect16`): `$name`
/// writes the closest hit (t, triangle index) of each of up to `$lanes` rays into `hits`.
macro_rules! packet_query {
    ($name:ident, $rayhit:ident, $ray:ident, $hit:ident, $call:ident, $lanes:literal) => {
        impl Embree {
            /// Closest hits of up to this many rays at once (Embree's packet query).
            pub fn $name(&self, rays: &[Ray], hits: &mut [Option<(f32, u32)>]) {
                assert!(rays.len() <= $lanes && hits.len() == rays.len());
                let lane =
                    |f: &dyn Fn(&Ray) -> f32| std::array::from_fn(|i| rays.get(i).map_or(0.0, f));
                let mut padded = PaddedRayHitN {
                    rayhit: $rayhit {
                        ray: $ray {
                            org_x: lane(&|r| r.origin.x),
                            org_y: lane(&|r| r.origin.y),
                            org_z: lane(&|r| r.origin.z),
                            tnear: lane(&|r| r.t_min),
                            dir_x: lane(&|r| r.direction.x),
                            dir_y: lane(&|r| r.direction.y),
                            dir_z: lane(&|r| r.direction.z),
                            time: [0.0; $lanes],
                            tfar: lane(&|r| r.t_max),
                            mask: [u32::MAX; $lanes],
                            id: [0; $lanes],
                            flags: [0; $lanes],
                        },
                        hit: $hit {
                            Ng_x: [0.0; $lanes],
                            Ng_y: [0.0; $lanes],
                            Ng_z: [0.0; $lanes],
                            u: [0.0; $lanes],
                            v: [0.0; $lanes],
                            primID: [u32::MAX; $lanes],
                            geomID: [u32::MAX; $lanes],
                            instID: [[u32::MAX; $lanes]],
                        },
                    },
                    _room: [u32::MAX; 32],
                };
                let valid: [i32; $lanes] = std::array::from_fn(|i| -i32::from(i < rays.len()));
                // SAFETY: the scene is committed; `valid` has a lane per ray slot and
                // `padded` is aligned as Embree requires and has room behind the struct.
                unsafe { $call(valid.as_ptr(), self.scene, &mut padded.rayhit, null_mut()) };
                let rayhit = &padded.rayhit;
                for (i, hit) in hits.iter_mut().enumerate() {
                    *hit = (rayhit.hit.geomID[i] != u32::MAX)
                        .then_some((rayhit.ray.tfar[i], rayhit.hit.primID[i]));
                }
            }
        }
    };
}

packet_query!(intersect8, RTCRayHit8, RTCRay8, RTCHit8, rtcIntersect8, 8);
packet_query!(
    intersect16,
    RTCRayHit16,
    RTCRay16,
    RTCHit16,
    rtcIntersect16,
    16
);

impl Embree {
    /// The widest packet Embree traces natively on this processor: 16, 8 or 1.
    pub fn native_packet(&self) -> usize {
        // SAFETY: a property query of the live device.
        let supported = |p| unsafe { rtcGetDeviceProperty(self.device, p) } != 0;
        if supported(RTCDeviceProperty::NATIVE_RAY16_SUPPORTED) {
            16
        } else if supported(RTCDeviceProperty::NATIVE_RAY8_SUPPORTED) {
            8
        } else {
            1
        }
    }
}

impl Drop for Embree {
    fn drop(&mut self) {
        // SAFETY: both handles were created in `build` and are released once.
        unsafe {
            rtcReleaseScene(self.scene);
            rtcReleaseDevice(self.device);
        }
    }
}
