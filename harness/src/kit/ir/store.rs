//! **VPL store**: the VPLs a frame is lit by, on the GPU, indexed by slot.
//!
//! Reads: a CPU list of (slot, [`Vpl`]) ([`VplStore::write`]) — or nothing, when a GPU pass
//! writes the buffer itself (bind [`VplStore::buffer`] read-write and declare it with
//! [`VplStore::wgsl`]`(group, binding, true)`).
//! Writes: one storage buffer `VplStoreData { header: vec4<u32>, items: array<GpuVpl> }` of
//! `capacity` items: `header.x` = number of slots in use (the highest used slot + 1),
//! `header.yzw` = the bits of three `f32`s, the VPLs' summed flux per channel (what the
//! accumulation's irradiance clamp is relative to; a GPU pass that fills the store writes it
//! too); item k is the VPL in slot k (a zero flux marks an empty slot, which every lookup
//! skips).
//!
//! A VPL's slot is also its shadow-map slot in a [`super::atlas::ShadowAtlas`] and decides its
//! interleaving tile (`slot mod T`), so incremental techniques that keep a VPL in its slot keep
//! the interleaving pattern when other VPLs come and go.

use bytemuck::{Pod, Zeroable};

use crate::cpu::vpl::{frame_from_normal, Vpl};
use crate::gpu::GpuContext;
use crate::{Error, Result};

/// GPU layout of `GpuVpl` (the WGSL module `gibench::vpl_store`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct GpuVpl {
    /// xyz: position; w: the slot (its shadow-map slot).
    pub position: [f32; 4],
    /// xyz: unit normal.
    pub normal: [f32; 4],
    /// rgb: flux leaving the surface (the VPL emits flux/π · cos θ).
    pub flux: [f32; 4],
    /// The VPL's frame about its normal ([`frame_from_normal`]), xyz; used by paraboloid maps.
    pub tangent: [f32; 4],
    pub bitangent: [f32; 4],
}

impl GpuVpl {
    /// The GPU form of `vpl` in `slot`.
    pub fn new(slot: u32, vpl: &Vpl) -> GpuVpl {
        let (t, b) = frame_from_normal(vpl.normal);
        GpuVpl {
            position: vpl.position.extend(slot as f32).to_array(),
            normal: vpl.normal.extend(0.0).to_array(),
            flux: vpl.flux.extend(0.0).to_array(),
            tangent: t.extend(0.0).to_array(),
            bitangent: b.extend(0.0).to_array(),
        }
    }
}

/// Bytes before the first item.
const HEADER: u64 = 16;

/// The slot-indexed VPL buffer (see the module docs).
pub struct VplStore {
    buffer: wgpu::Buffer,
    capacity: u32,
}

impl VplStore {
    /// A store of `capacity` slots, zeroed (no VPLs).
    pub fn new(gpu: &GpuContext, capacity: u32) -> Result<VplStore> {
        if capacity == 0 {
            return Err(Error::param("vpls", "at least one VPL slot is needed"));
        }
        let size = HEADER + capacity as u64 * std::mem::size_of::<GpuVpl>() as u64;
        let max = gpu.max_storage_buffer();
        if size > max {
            return Err(Error::param(
                "vpls",
                format!(
                    "{capacity} VPLs need a {size}-byte buffer; the adapter allows {max} bytes"
                ),
            ));
        }
        let buffer = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("vpl store"),
            size,
            usage: wgpu::BufferUsages::STORAGE
                | wgpu::BufferUsages::COPY_DST
                | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        Ok(VplStore { buffer, capacity })
    }

    /// Number of slots.
    pub fn capacity(&self) -> u32 {
        self.capacity
    }

    /// The storage buffer (header, then `capacity` items).
    pub fn buffer(&self) -> &wgpu::Buffer {
        &self.buffer
    }

    /// Uploads `vpls` (slot, VPL): slots without a VPL up to the highest used one get a
    /// zero-flux item; slots at or beyond the capacity are dropped. The header gets the slots
    /// in use and the summed flux of the VPLs kept. Returns the slots in use.
    pub fn write(&self, queue: &wgpu::Queue, vpls: &[(u32, Vpl)]) -> u32 {
        let n = vpls
            .iter()
            .map(|(slot, _)| *slot as usize + 1)
            .max()
            .unwrap_or(0)
            .min(self.capacity as usize);
        let mut data = vec![GpuVpl::zeroed(); n];
        let mut flux = glam::DVec3::ZERO;
        for (slot, v) in vpls.iter().filter(|(slot, _)| (*slot as usize) < n) {
            data[*slot as usize] = GpuVpl::new(*slot, v);
            flux += v.flux.as_dvec3();
        }
        let f = flux.as_vec3();
        let header = [n as u32, f.x.to_bits(), f.y.to_bits(), f.z.to_bits()];
        queue.write_buffer(&self.buffer, 0, bytemuck::bytes_of(&header));
        if !data.is_empty() {
            queue.write_buffer(&self.buffer, HEADER, bytemuck::cast_slice(&data));
        }
        n as u32
    }

    /// Declarations for a shader that binds the store at (`group`, `binding`) as `vpl_store`,
    /// read-only or read-write.
    pub fn wgsl(group: u32, binding: u32, read_write: bool) -> String {
        let access = if read_write { "read_write" } else { "read" };
        format!(
            "#import gibench::vpl_store\n@group({group}) @binding({binding}) var<storage, {access}> vpl_store: VplStoreData;\n"
        )
    }

    /// A bind-group-layout entry for the store, read-only or read-write, compute only.
    pub fn layout_entry(binding: u32, read_write: bool) -> wgpu::BindGroupLayoutEntry {
        crate::kit::passes::storage_entry(binding, !read_write)
    }
}
