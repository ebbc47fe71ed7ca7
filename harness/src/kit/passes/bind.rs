//! Bind-group layout entries and bind-group entries: one small constructor for each kind of
//! binding the passes declare, so no pass spells out a `BindGroupLayoutEntry` by hand.

/// A buffer layout entry of any buffer binding type (the base of the buffer constructors here).
fn buffer(
    binding: u32,
    visibility: wgpu::ShaderStages,
    ty: wgpu::BufferBindingType,
    has_dynamic_offset: bool,
    min_binding_size: Option<wgpu::BufferSize>,
) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Buffer {
            ty,
            has_dynamic_offset,
            min_binding_size,
        },
        count: None,
    }
}

/// A uniform-buffer layout entry.
pub fn uniform_entry(
    binding: u32,
    visibility: wgpu::ShaderStages,
    dynamic: bool,
) -> wgpu::BindGroupLayoutEntry {
    buffer(
        binding,
        visibility,
        wgpu::BufferBindingType::Uniform,
        dynamic,
        None,
    )
}

/// A storage-buffer layout entry, read-only or read-write, compute only.
pub fn storage_entry(binding: u32, read_only: bool) -> wgpu::BindGroupLayoutEntry {
    buffer(
        binding,
        wgpu::ShaderStages::COMPUTE,
        wgpu::BufferBindingType::Storage { read_only },
        false,
        None,
    )
}

/// A read-only storage-buffer layout entry visible to `visibility`.
pub fn read_storage_entry(
    binding: u32,
    visibility: wgpu::ShaderStages,
) -> wgpu::BindGroupLayoutEntry {
    buffer(
        binding,
        visibility,
        wgpu::BufferBindingType::Storage { read_only: true },
        false,
        None,
    )
}

/// A read-only storage-buffer layout entry bound at a dynamic offset, `min_size` bytes a binding.
pub fn dynamic_storage_entry(
    binding: u32,
    visibility: wgpu::ShaderStages,
    min_size: u64,
) -> wgpu::BindGroupLayoutEntry {
    buffer(
        binding,
        visibility,
        wgpu::BufferBindingType::Storage { read_only: true },
        true,
        wgpu::BufferSize::new(min_size),
    )
}

/// A read-only storage-buffer layout entry for a pass's parameter block.
///
/// Parameters a shader branches or loops on are bound as read-only storage buffers, not
/// uniforms: lavapipe (Mesa 22.3) inlines uniform values that control flow depends on and
/// compiles a fresh shader variant for every draw or dispatch that reads them, never freeing it
/// (about 0.7 MB per frame for the direct-light pass alone: memory grew without bound).
pub fn params_entry(binding: u32, visibility: wgpu::ShaderStages) -> wgpu::BindGroupLayoutEntry {
    read_storage_entry(binding, visibility)
}

/// Buffer usages of a parameter block bound with [`params_entry`] and written by the queue.
pub const PARAMS_USAGE: wgpu::BufferUsages =
    wgpu::BufferUsages::STORAGE.union(wgpu::BufferUsages::COPY_DST);

/// A sampled-texture layout entry.
pub fn texture_entry(
    binding: u32,
    visibility: wgpu::ShaderStages,
    sample_type: wgpu::TextureSampleType,
    dim: wgpu::TextureViewDimension,
) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Texture {
            sample_type,
            view_dimension: dim,
            multisampled: false,
        },
        count: None,
    }
}

/// A write-only 2D storage-texture layout entry of `format`, compute only.
pub fn storage_texture_entry(
    binding: u32,
    format: wgpu::TextureFormat,
) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::StorageTexture {
            access: wgpu::StorageTextureAccess::WriteOnly,
            format,
            view_dimension: wgpu::TextureViewDimension::D2,
        },
        count: None,
    }
}

/// A sampler layout entry of `kind`.
pub fn sampler_entry(
    binding: u32,
    visibility: wgpu::ShaderStages,
    kind: wgpu::SamplerBindingType,
) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Sampler(kind),
        count: None,
    }
}

/// A bind-group entry binding the whole of `buffer` at `binding`.
pub fn bind_buffer(binding: u32, buffer: &wgpu::Buffer) -> wgpu::BindGroupEntry<'_> {
    wgpu::BindGroupEntry {
        binding,
        resource: buffer.as_entire_binding(),
    }
}
