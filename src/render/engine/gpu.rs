//! Finding and opening a GPU. On machines without one (CI, the development machines) wgpu
//! finds Mesa's software Vulkan (lavapipe, `apt-get install mesa-vulkan-drivers`).

use std::fmt;

#[derive(Debug, thiserror::Error)]
pub enum GpuError {
    #[error(
        "no GPU adapter found ({0}); install a Vulkan driver, e.g. `apt-get install mesa-vulkan-drivers libvulkan1`"
    )]
    NoAdapter(String),
    #[error("the GPU adapter refused a device: {0}")]
    Device(String),
    /// The adapter cannot hold a texture the renderer needs (`check_texture_limits`).
    #[error("the GPU adapter is too small for this run: {0}")]
    Limits(String),
    #[error("GPU readback failed: {0}")]
    Readback(String),
    /// The device could not allocate what a frame or a dispatch needs.
    #[error("the GPU ran out of memory {0}; use a smaller size")]
    OutOfMemory(String),
    /// A device error wgpu would otherwise have panicked on (its default handler).
    #[error("the GPU refused {0}")]
    Refused(String),
    /// A GPU timing that came out meaningless (not positive): noise swamped the work.
    #[error("GPU timing failed: {0}")]
    Timing(String),
    /// No window could be opened or drawn into (no display, no compatible surface).
    #[error("{0}")]
    Window(String),
}

/// An open device and its queue.
pub struct Gpu {
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    pub info: wgpu::AdapterInfo,
}

impl fmt::Debug for Gpu {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        write!(f, "Gpu({} / {:?} / {:?})", self.info.name, self.info.backend, self.info.device_type)
    }
}

impl Gpu {
    /// Opens the default adapter without a window (a software adapter if that is all there is).
    pub fn headless() -> Result<Gpu, GpuError> {
        // Vulkan, Metal or DX12 (not GL): headless GL would probe for a display and complain.
        let mut descriptor = wgpu::InstanceDescriptor::new_without_display_handle();
        descriptor.backends = wgpu::Backends::PRIMARY;
        let instance = wgpu::Instance::new(descriptor.with_env());
        let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            compatible_surface: None,
            ..Default::default()
        }))
        .map_err(|e| {
            // `with_env` lets WGPU_BACKEND choose the backends: a typo there, not a driver,
            // may be why there is none. Where it already takes Vulkan (as wgpu reads it:
            // "vulkan" or "vk", alone or in a list) the hint would repeat it (a hostile-input
            // review), and the driver is what is missing.
            let chosen = std::env::var("WGPU_BACKEND")
                .ok()
                .filter(|v| !wgpu::Backends::from_comma_list(v).contains(wgpu::Backends::VULKAN))
                .map(|v| format!("; WGPU_BACKEND={v:?} chose the backends tried (unset it, or set it to vulkan)"))
                .unwrap_or_default();
            GpuError::NoAdapter(format!("{e}{chosen}"))
        })?;
        Gpu::open(&adapter)
    }

    /// Opens a device on `adapter`, with GPU timestamps where the adapter has them (for
    /// `bench render`).
    pub fn open(adapter: &wgpu::Adapter) -> Result<Gpu, GpuError> {
        let info = adapter.get_info();
        check_texture_limits(&adapter.limits())?;
        let required_features = adapter.features() & wgpu::Features::TIMESTAMP_QUERY;
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("snakeskin"),
            required_features,
            required_limits: wgpu::Limits::downlevel_defaults().using_resolution(adapter.limits()),
            ..Default::default()
        }))
        .map_err(|e| GpuError::Device(e.to_string()))?;
        Ok(Gpu { device, queue, info })
    }

    /// Runs `work` with the device's out-of-memory and validation errors caught as
    /// `GpuError`s (`what` names the work in the message). Outside such a scope wgpu hands
    /// them to its default handler, which panics: an 8192² frame under a memory limit
    /// ended the process with exit code 101.
    pub fn checked<T>(&self, what: &str, work: impl FnOnce() -> Result<T, GpuError>) -> Result<T, GpuError> {
        let out_of_memory = self.device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
        let invalid = self.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let result = work();
        // Popped in reverse order of their pushing.
        let invalid = pollster::block_on(invalid.pop());
        if let Some(e) = pollster::block_on(out_of_memory.pop()) {
            return Err(GpuError::OutOfMemory(format!("{what} ({e})")));
        }
        if let Some(e) = invalid {
            return Err(GpuError::Refused(format!("{what}: {e}")));
        }
        result
    }

    /// A short description of the adapter, for reports.
    pub fn describe(&self) -> String {
        format!("{} ({:?}, {:?})", self.info.name, self.info.backend, self.info.device_type)
    }
}

/// The renderer's largest textures against what the adapter can hold: the film LUT is a 2-D
/// texture and the coupling table a 3-D texture with one column or layer per LUT thickness
/// column (`lut::DEFAULT_WIDTH`, 320). Vulkan promises only 256 texels along each axis of a
/// 3-D texture (`maxImageDimension3D`), so an adapter at that minimum is refused here with
/// the reason, rather than by a validation error when the texture is made.
fn check_texture_limits(limits: &wgpu::Limits) -> Result<(), GpuError> {
    let columns = crate::optics::lut::DEFAULT_WIDTH as u32;
    if limits.max_texture_dimension_3d < columns || limits.max_texture_dimension_2d < columns {
        return Err(GpuError::Limits(format!(
            "the adapter's largest 3-D texture is {} texels per axis (2-D: {}); the film's coupling \
             table needs {columns}",
            limits.max_texture_dimension_3d, limits.max_texture_dimension_2d
        )));
    }
    Ok(())
}

/// A compute shader's storage output and the mappable buffer the CPU reads it from: bind
/// `buffer`, record `copy_out` after the pass, submit, then `read`.
pub struct StorageOutput {
    pub buffer: wgpu::Buffer,
    readback: wgpu::Buffer,
}

impl StorageOutput {
    pub fn new(device: &wgpu::Device, label: &str, size: u64) -> StorageOutput {
        let buffer = |label: &str, usage| {
            device.create_buffer(&wgpu::BufferDescriptor { label: Some(label), size, usage, mapped_at_creation: false })
        };
        StorageOutput {
            buffer: buffer(label, wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC),
            readback: buffer(&format!("{label} readback"), wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST),
        }
    }

    /// Records the copy of the output into the mappable buffer.
    pub fn copy_out(&self, encoder: &mut wgpu::CommandEncoder) {
        encoder.copy_buffer_to_buffer(&self.buffer, 0, &self.readback, 0, self.buffer.size());
    }

    /// The output's bytes, once the submission that holds `copy_out` is done (waits for it).
    pub fn read(&self, device: &wgpu::Device) -> Result<Vec<u8>, GpuError> {
        map_read(device, &self.readback)
    }
}

/// Maps a buffer for reading, waits for the GPU, and returns a copy of its bytes.
pub fn map_read(device: &wgpu::Device, buffer: &wgpu::Buffer) -> Result<Vec<u8>, GpuError> {
    map_read_with(device, buffer, <[u8]>::to_vec)
}

/// Maps a buffer for reading, waits for the GPU, and returns what `read` makes of its bytes
/// (a frame's rows without their padding: a copy of the whole buffer first cost 4 bytes a
/// pixel more at the frame's peak).
pub fn map_read_with<T>(
    device: &wgpu::Device,
    buffer: &wgpu::Buffer,
    read: impl FnOnce(&[u8]) -> T,
) -> Result<T, GpuError> {
    let slice = buffer.slice(..);
    let (sender, receiver) = std::sync::mpsc::channel();
    slice.map_async(wgpu::MapMode::Read, move |result| {
        let _ = sender.send(result);
    });
    device.poll(wgpu::PollType::wait_indefinitely()).map_err(|e| GpuError::Readback(e.to_string()))?;
    receiver.recv().map_err(|e| GpuError::Readback(e.to_string()))?.map_err(|e| GpuError::Readback(e.to_string()))?;
    let data = read(&slice.get_mapped_range().map_err(|e| GpuError::Readback(e.to_string()))?);
    buffer.unmap();
    Ok(data)
}

/// A uniform-buffer entry of a bind group layout.
pub fn uniform_entry(binding: u32, visibility: wgpu::ShaderStages) -> wgpu::BindGroupLayoutEntry {
    buffer_entry(binding, visibility, wgpu::BufferBindingType::Uniform)
}

/// A storage-buffer entry of a bind group layout.
pub fn storage_entry(binding: u32, visibility: wgpu::ShaderStages, read_only: bool) -> wgpu::BindGroupLayoutEntry {
    buffer_entry(binding, visibility, wgpu::BufferBindingType::Storage { read_only })
}

/// A 2D float texture entry of a bind group layout.
pub fn texture_entry(binding: u32, visibility: wgpu::ShaderStages, filterable: bool) -> wgpu::BindGroupLayoutEntry {
    texture_entry_of(binding, visibility, filterable, wgpu::TextureViewDimension::D2)
}

/// A float texture entry of the given dimension.
pub fn texture_entry_of(
    binding: u32,
    visibility: wgpu::ShaderStages,
    filterable: bool,
    view_dimension: wgpu::TextureViewDimension,
) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Float { filterable },
            view_dimension,
            multisampled: false,
        },
        count: None,
    }
}

/// A filtering sampler entry of a bind group layout.
pub fn sampler_entry(binding: u32, visibility: wgpu::ShaderStages) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
        count: None,
    }
}

fn buffer_entry(
    binding: u32,
    visibility: wgpu::ShaderStages,
    ty: wgpu::BufferBindingType,
) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Buffer { ty, has_dynamic_offset: false, min_binding_size: None },
        count: None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An adapter at Vulkan's minimum 3-D size is refused with both numbers in the message;
    /// wgpu's defaults (2048) pass.
    #[test]
    fn an_adapter_too_small_for_the_coupling_table_is_refused_with_the_sizes() {
        assert!(check_texture_limits(&wgpu::Limits::default()).is_ok());
        let small = wgpu::Limits { max_texture_dimension_3d: 256, ..wgpu::Limits::default() };
        let message = check_texture_limits(&small).expect_err("256 < 320").to_string();
        assert!(message.contains("256") && message.contains("320"), "{message}");
        let just = wgpu::Limits { max_texture_dimension_3d: 320, ..wgpu::Limits::default() };
        assert!(check_texture_limits(&just).is_ok());
    }
}
