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

/// A bind group declared binding by binding, kajiya-style: each call adds the next binding
/// (0, 1, 2, … in the order of the calls, as the shader numbers them) with both its layout entry
/// and the resource bound there, so a pass's layout and its group come from one declaration and
/// cannot disagree. No render graph: [`Bindings::build`] makes the two wgpu objects and nothing
/// else.
///
/// ```text
/// let export = Bindings::new("rsm export", wgpu::ShaderStages::COMPUTE)
///     .params(&params)
///     .texture(&depth_view)
///     .write(&positions)
///     .build(device);
/// ```
pub struct Bindings<'a> {
    label: &'a str,
    first: u32,
    visibility: wgpu::ShaderStages,
    entries: Vec<wgpu::BindGroupLayoutEntry>,
    resources: Vec<wgpu::BindingResource<'a>>,
}

/// A bind group and its layout, made by [`Bindings::build`].
pub struct Bound {
    /// The layout, for the pipelines that use the group.
    pub layout: wgpu::BindGroupLayout,
    /// The group, for `set_bind_group`.
    pub group: wgpu::BindGroup,
}

impl<'a> Bindings<'a> {
    /// No bindings yet; those added are visible to `visibility`.
    pub fn new(label: &'a str, visibility: wgpu::ShaderStages) -> Bindings<'a> {
        Bindings {
            label,
            first: 0,
            visibility,
            entries: Vec::new(),
            resources: Vec::new(),
        }
    }

    /// Numbers the bindings from `first` instead of 0 (a shader whose entry points share one
    /// group number and split its bindings between them). Before any binding is added.
    pub fn first_binding(mut self, first: u32) -> Bindings<'a> {
        assert!(self.entries.is_empty(), "first_binding after a binding");
        self.first = first;
        self
    }

    /// The next binding: its layout entry made by `entry` from its number and the current
    /// visibility, and the resource bound there.
    pub fn with(
        mut self,
        entry: impl FnOnce(u32, wgpu::ShaderStages) -> wgpu::BindGroupLayoutEntry,
        resource: wgpu::BindingResource<'a>,
    ) -> Bindings<'a> {
        let binding = self.first + self.entries.len() as u32;
        self.entries.push(entry(binding, self.visibility));
        self.resources.push(resource);
        self
    }

    /// A parameter block ([`params_entry`]: a read-only storage buffer).
    pub fn params(self, buffer: &'a wgpu::Buffer) -> Bindings<'a> {
        self.with(params_entry, buffer.as_entire_binding())
    }

    /// A uniform buffer, whole or the part `resource` names (a view's slot).
    pub fn uniform(self, resource: wgpu::BindingResource<'a>) -> Bindings<'a> {
        self.with(|b, v| uniform_entry(b, v, false), resource)
    }

    /// A uniform buffer bound at a dynamic offset (`set_bind_group`'s offsets pick the slot);
    /// `resource` is the first slot.
    pub fn dynamic_uniform(self, resource: wgpu::BindingResource<'a>) -> Bindings<'a> {
        self.with(|b, v| uniform_entry(b, v, true), resource)
    }

    /// A storage buffer the pass reads.
    pub fn read(self, buffer: &'a wgpu::Buffer) -> Bindings<'a> {
        self.with(read_storage_entry, buffer.as_entire_binding())
    }

    /// A storage buffer the pass writes (and may read).
    pub fn write(self, written: &'a wgpu::Buffer) -> Bindings<'a> {
        let entry = |b, v| {
            let ty = wgpu::BufferBindingType::Storage { read_only: false };
            buffer(b, v, ty, false, None)
        };
        self.with(entry, written.as_entire_binding())
    }

    /// A 2D texture of unfilterable floats (render targets read back by a compute pass).
    pub fn texture(self, view: &'a wgpu::TextureView) -> Bindings<'a> {
        let unfilterable = wgpu::TextureSampleType::Float { filterable: false };
        self.texture_of(view, unfilterable, wgpu::TextureViewDimension::D2)
    }

    /// A texture of `sample_type` and `dim`.
    fn texture_of(
        self,
        view: &'a wgpu::TextureView,
        sample_type: wgpu::TextureSampleType,
        dim: wgpu::TextureViewDimension,
    ) -> Bindings<'a> {
        let entry = |b, v| texture_entry(b, v, sample_type, dim);
        self.with(entry, wgpu::BindingResource::TextureView(view))
    }

    /// A write-only 2D storage texture of `format` (compute only).
    pub fn storage_texture(
        self,
        view: &'a wgpu::TextureView,
        format: wgpu::TextureFormat,
    ) -> Bindings<'a> {
        let entry = |b, _| storage_texture_entry(b, format);
        self.with(entry, wgpu::BindingResource::TextureView(view))
    }

    /// The layout entries declared so far, in binding order.
    pub fn entries(&self) -> &[wgpu::BindGroupLayoutEntry] {
        &self.entries
    }

    /// The layout and the group.
    pub fn build(self, device: &wgpu::Device) -> Bound {
        let layout = self.layout(device);
        let group = self.group(device, &layout);
        Bound { layout, group }
    }

    /// The layout alone (for pipelines shared by many groups of this declaration; the
    /// resources are not used).
    pub fn layout(&self, device: &wgpu::Device) -> wgpu::BindGroupLayout {
        device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some(self.label),
            entries: &self.entries,
        })
    }

    /// The group alone, for `layout` made by [`Bindings::layout`] of the same declaration.
    pub fn group(self, device: &wgpu::Device, layout: &wgpu::BindGroupLayout) -> wgpu::BindGroup {
        let entries: Vec<wgpu::BindGroupEntry> = (self.entries.iter())
            .zip(self.resources)
            .map(|(e, resource)| wgpu::BindGroupEntry {
                binding: e.binding,
                resource,
            })
            .collect();
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some(self.label),
            layout,
            entries: &entries,
        })
    }
}
