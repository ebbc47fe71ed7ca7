//! Reading buffers and textures back from the GPU and writing images: PNG for what a person looks at,
//! OpenEXR (32-bit float RGB) for irradiance buffers. Both are written atomically.

use std::path::Path;

use crate::gpu::GpuContext;
use crate::{Error, Result};

/// Copies a 2D texture to the CPU, tightly packed rows (flushes the queue).
pub fn read_texture(gpu: &GpuContext, texture: &wgpu::Texture) -> Result<Vec<u8>> {
    let (w, h) = (texture.width(), texture.height());
    let bpp = texture
        .format()
        .block_copy_size(None)
        .ok_or_else(|| Error::Gpu(format!("cannot read back a {:?} texture", texture.format())))?;
    let row = w * bpp;
    let padded =
        row.div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
    let buffer = gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("readback"),
        size: (padded * h) as u64,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut enc = gpu.device.create_command_encoder(&Default::default());
    enc.copy_texture_to_buffer(
        texture.as_image_copy(),
        wgpu::TexelCopyBufferInfo {
            buffer: &buffer,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(padded),
                rows_per_image: Some(h),
            },
        },
        wgpu::Extent3d {
            width: w,
            height: h,
            depth_or_array_layers: 1,
        },
    );
    gpu.queue.submit([enc.finish()]);
    let slice = buffer.slice(..);
    slice.map_async(wgpu::MapMode::Read, |_| {});
    gpu.flush()?;
    let mapped = gpu.mapped(&slice, "a readback buffer")?;
    let mut out = Vec::with_capacity((row * h) as usize);
    for y in 0..h {
        let start = (y * padded) as usize;
        out.extend_from_slice(&mapped[start..start + row as usize]);
    }
    drop(mapped);
    buffer.unmap();
    Ok(out)
}

/// Copies a whole buffer (COPY_SRC) to the CPU after the queued work (flushes the queue and
/// makes a staging buffer: for tests, checks and exports, not a frame loop).
pub fn read_buffer(gpu: &GpuContext, buffer: &wgpu::Buffer) -> Result<Vec<u8>> {
    let staging = gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("buffer readback"),
        size: buffer.size(),
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut enc = gpu.device.create_command_encoder(&Default::default());
    enc.copy_buffer_to_buffer(buffer, 0, &staging, 0, buffer.size());
    gpu.queue.submit([enc.finish()]);
    let slice = staging.slice(..);
    slice.map_async(wgpu::MapMode::Read, |_| {});
    gpu.flush()?;
    let bytes = gpu.mapped(&slice, "a readback buffer")?.to_vec();
    staging.unmap();
    Ok(bytes)
}

/// IEEE half → f32.
pub fn f16_to_f32(bits: u16) -> f32 {
    let sign = if bits & 0x8000 != 0 { -1.0 } else { 1.0 };
    let exp = ((bits >> 10) & 0x1f) as i32;
    let mant = (bits & 0x3ff) as f32;
    sign * match exp {
        0 => mant * 2f32.powi(-24),
        31 => {
            if mant == 0.0 {
                f32::INFINITY
            } else {
                f32::NAN
            }
        }
        _ => (1.0 + mant / 1024.0) * 2f32.powi(exp - 15),
    }
}

/// Reads an Rgba16Float texture back as RGB f32 triples.
pub fn read_rgb_f32(gpu: &GpuContext, texture: &wgpu::Texture) -> Result<Vec<[f32; 3]>> {
    if texture.format() != wgpu::TextureFormat::Rgba16Float {
        return Err(Error::Gpu(format!(
            "expected an Rgba16Float texture, got {:?}",
            texture.format()
        )));
    }
    let bytes = read_texture(gpu, texture)?;
    Ok(bytes
        .chunks_exact(8)
        .map(|c| {
            let h = |i: usize| f16_to_f32(u16::from_le_bytes([c[2 * i], c[2 * i + 1]]));
            [h(0), h(1), h(2)]
        })
        .collect())
}

/// Writes an RGBA8 image as PNG: as RGB when every pixel is opaque (every image gibench shows
/// is), and at the encoder's best compression with adaptive filters rather than its fast
/// default, so that the images a checkout keeps stay small (issue 51).
pub fn write_png(path: &Path, size: [u32; 2], rgba8: &[u8]) -> Result<()> {
    use image::codecs::png::{CompressionType, FilterType, PngEncoder};
    use image::{ExtendedColorType, ImageEncoder};
    let mismatch = || {
        Error::Invalid(format!(
            "{}: image data does not match {}x{}",
            path.display(),
            size[0],
            size[1]
        ))
    };
    let pixels = size[0] as usize * size[1] as usize;
    if rgba8.len() != pixels * 4 {
        return Err(mismatch());
    }
    let opaque = rgba8.chunks_exact(4).all(|p| p[3] == 255);
    let rgb: Vec<u8>;
    let (data, color) = if opaque {
        rgb = rgba8
            .chunks_exact(4)
            .flat_map(|p| [p[0], p[1], p[2]])
            .collect();
        (&rgb[..], ExtendedColorType::Rgb8)
    } else {
        (rgba8, ExtendedColorType::Rgba8)
    };
    let mut bytes = Vec::new();
    PngEncoder::new_with_quality(&mut bytes, CompressionType::Best, FilterType::Adaptive)
        .write_image(data, size[0], size[1], color)
        .map_err(|e| Error::bad_file(path, format!("PNG encoding failed: {e}")))?;
    crate::output::write_atomic(path, &bytes)
}

/// Writes RGB floats as a 32-bit float OpenEXR file.
pub fn write_exr(path: &Path, size: [u32; 2], rgb: &[[f32; 3]]) -> Result<()> {
    use exr::prelude::{Image, SpecificChannels, Vec2, WritableImage};
    let (w, h) = (size[0] as usize, size[1] as usize);
    if rgb.len() != w * h {
        return Err(Error::Invalid(format!(
            "{}: image data does not match {w}x{h}",
            path.display()
        )));
    }
    let channels = SpecificChannels::rgb(|p: Vec2<usize>| {
        let c = rgb[p.y() * w + p.x()];
        (c[0], c[1], c[2])
    });
    let image = Image::from_channels((w, h), channels);
    let mut bytes = std::io::Cursor::new(Vec::new());
    // One thread: with parallel compression the chunks land in completion order, so the same
    // pixels gave different files.
    image
        .write()
        .non_parallel()
        .to_buffered(&mut bytes)
        .map_err(|e| Error::bad_file(path, format!("EXR encoding failed: {e}")))?;
    crate::output::write_atomic(path, bytes.get_ref())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The same pixels give the same bytes, every time.
    #[test]
    fn exr_files_of_identical_pixels_are_identical() {
        let dir = tempfile::tempdir().unwrap();
        let (w, h) = (256usize, 192usize);
        let rgb: Vec<[f32; 3]> = (0..w * h)
            .map(|i| [i as f32 * 0.37 % 7.0, (i % 13) as f32, 0.5])
            .collect();
        let first = dir.path().join("a.exr");
        write_exr(&first, [w as u32, h as u32], &rgb).unwrap();
        let a = std::fs::read(&first).unwrap();
        for k in 0..8 {
            let p = dir.path().join(format!("b{k}.exr"));
            write_exr(&p, [w as u32, h as u32], &rgb).unwrap();
            assert!(std::fs::read(&p).unwrap() == a, "write {k} differs");
        }
    }

    #[test]
    fn half_conversion() {
        assert_eq!(f16_to_f32(0x3c00), 1.0);
        assert_eq!(f16_to_f32(0xc000), -2.0);
        assert_eq!(f16_to_f32(0x7bff), 65504.0);
        assert_eq!(f16_to_f32(0x0001), 2f32.powi(-24));
        assert!(f16_to_f32(0x7c00).is_infinite());
    }
}
