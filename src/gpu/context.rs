//! The device: a Vulkan adapter and its device and queue through wgpu, the compute kernels
//! built from WGSL, and the few operations every stage uses (buffers, bind groups,
//! dispatches, read-backs). Errors the device reports are kept and returned by
//! [`Context::check`], never panicked on.

use crate::Error;
use crate::world::gpu_error;
use std::sync::{Arc, Mutex};
use std::task::{Context as TaskContext, Poll, Wake, Waker};

/// Threads per workgroup of every kernel (`@workgroup_size(256)` in the shaders).
pub(super) const WORKGROUP: u32 = 256;
/// The most workgroups a dispatch has along one axis (WebGPU's limit); larger dispatches
/// are laid out over x and y (`item` in shaders/common.wgsl).
const MAX_GROUPS: u32 = 65_535;
/// Storage buffers the largest kernel binds (project.wgsl).
const STORAGE_BUFFERS: u32 = 12;

/// The device and queue, with the first error the device reported since the last check.
pub(super) struct Context {
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    /// The adapter's name and driver, for messages.
    pub adapter: String,
    /// Where the handler of a device projfluid opened keeps the errors no scope caught; a
    /// caller's device keeps its own handler, and this stays empty.
    errors: Arc<Mutex<Option<String>>>,
    /// The staging buffer of the last read-back, kept for the next one that fits in it.
    staging: Mutex<Option<wgpu::Buffer>>,
}

/// Error scopes over one operation on the device ([`Context::scope`]): every error the
/// device reports for the work issued while they are open is returned by [`Scope::close`].
/// Dropped without closing, they are popped and their errors dropped.
pub(super) struct Scope {
    // Popped in this order, the reverse of their pushing, when dropped.
    validation: wgpu::ErrorScopeGuard,
    internal: wgpu::ErrorScopeGuard,
    memory: wgpu::ErrorScopeGuard,
    adapter: String,
}

impl Scope {
    /// Closes the scopes: `done`'s error if it failed, else the first error the device
    /// reported within them (out of memory as [`Error::OutOfMemory`]), else `done`'s value.
    pub fn close<T>(self, done: Result<T, Error>) -> Result<T, Error> {
        let Scope {
            validation,
            internal,
            memory,
            adapter,
        } = self;
        let validation = block_on(validation.pop());
        let internal = block_on(internal.pop());
        let memory = block_on(memory.pop());
        let value = done?;
        if let Some(e) = memory {
            return Err(Error::OutOfMemory(format!(
                "the GPU {adapter} ran out of memory: {e}"
            )));
        }
        match validation.or(internal) {
            Some(e) => Err(gpu_error(&format!("failed on the device {adapter}: {e}"))),
            None => Ok(value),
        }
    }
}

/// What a kernel binds at each slot of its bind group.
#[derive(Clone, Copy)]
pub(super) enum Slot {
    Uniform,
    Storage,
}

/// A WGSL module's compute pipelines, one per entry point, sharing one bind group layout.
pub(super) struct Kernel {
    pub layout: wgpu::BindGroupLayout,
    pub pipelines: Vec<wgpu::ComputePipeline>,
}

/// The error for a GPU backend that cannot run here: it names the backend and what is
/// missing.
fn unavailable(missing: &str) -> Error {
    gpu_error(&format!("cannot run: {missing}"))
}

impl Context {
    /// Opens the first Vulkan adapter (a discrete GPU preferred; Mesa's lavapipe serves where
    /// there is no GPU). Errors, naming what is missing, without a Vulkan loader or adapter,
    /// or when the adapter lacks the storage buffers the kernels bind.
    pub fn new() -> Result<Self, Error> {
        if wgpu::Instance::enabled_backend_features().is_empty() {
            return Err(unavailable(
                "wgpu has no backend for this platform in this build",
            ));
        }
        let mut desc = wgpu::InstanceDescriptor::new_without_display_handle();
        desc.backends = wgpu::Backends::VULKAN;
        let instance = wgpu::Instance::new(desc);
        let options = wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            force_fallback_adapter: false,
            compatible_surface: None,
            ..Default::default()
        };
        let adapter = block_on(instance.request_adapter(&options)).map_err(|e| {
            unavailable(&format!(
                "no Vulkan adapter was found ({e}); install a Vulkan driver and loader \
                 (on Debian: mesa-vulkan-drivers and libvulkan1 give the software device \
                 lavapipe)"
            ))
        })?;
        let info = adapter.get_info();
        let name = format!("{} ({}, {:?})", info.name, info.driver, info.device_type);
        let limits = adapter.limits();
        check_limits(&limits, &format!("the adapter {name}"))?;
        let required_limits = wgpu::Limits {
            max_storage_buffers_per_shader_stage: STORAGE_BUFFERS,
            max_storage_buffer_binding_size: limits.max_storage_buffer_binding_size,
            max_buffer_size: limits.max_buffer_size,
            ..wgpu::Limits::default()
        };
        let (device, queue) = block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("projfluid"),
            // Timestamps time the step's stages (timer.rs) where the adapter has them.
            required_features: adapter.features() & wgpu::Features::TIMESTAMP_QUERY,
            required_limits,
            experimental_features: wgpu::ExperimentalFeatures::disabled(),
            memory_hints: wgpu::MemoryHints::Performance,
            trace: wgpu::Trace::Off,
        }))
        .map_err(|e| unavailable(&format!("the adapter {name} gave no device: {e}")))?;
        let errors = Arc::new(Mutex::new(None));
        let sink = Arc::clone(&errors);
        device.on_uncaptured_error(Arc::new(move |e: wgpu::Error| {
            if let Ok(mut slot) = sink.lock() {
                slot.get_or_insert_with(|| e.to_string());
            }
        }));
        Ok(Self {
            device,
            queue,
            adapter: name,
            errors,
            staging: Mutex::new(None),
        })
    }

    /// The caller's `device` and `queue` (an engine's), on which the kernels' storage
    /// buffers must fit: errors, naming the limit, when the device binds fewer than the
    /// kernels need. Its uncaptured-error handler is left as it is: every operation of the
    /// stepper runs in error scopes ([`Context::scope`]).
    pub fn on(device: wgpu::Device, queue: wgpu::Queue) -> Result<Self, Error> {
        check_limits(&device.limits(), "the caller's device")?;
        Ok(Self {
            device,
            queue,
            adapter: "(the caller's device)".to_string(),
            errors: Arc::new(Mutex::new(None)),
            staging: Mutex::new(None),
        })
    }

    /// Opens error scopes over the work issued until [`Scope::close`].
    pub fn scope(&self) -> Scope {
        let memory = self.device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
        let internal = self.device.push_error_scope(wgpu::ErrorFilter::Internal);
        let validation = self.device.push_error_scope(wgpu::ErrorFilter::Validation);
        Scope {
            validation,
            internal,
            memory,
            adapter: self.adapter.clone(),
        }
    }

    /// The first error the device reported since the last check, as an [`Error`] naming the
    /// adapter (an allocation the device refused is [`Error::OutOfMemory`]).
    pub fn check(&self) -> Result<(), Error> {
        let taken = self.errors.lock().ok().and_then(|mut slot| slot.take());
        match taken {
            None => Ok(()),
            Some(message) if message.to_lowercase().contains("out of memory") => {
                Err(Error::OutOfMemory(format!(
                    "the GPU {} ran out of memory: {message}",
                    self.adapter
                )))
            }
            Some(message) => Err(gpu_error(&format!(
                "failed on the device {}: {message}",
                self.adapter
            ))),
        }
    }

    /// A storage buffer of `bytes` bytes (at least 16), zeroed, that copies may read and
    /// write.
    pub fn storage(&self, label: &str, bytes: u64) -> wgpu::Buffer {
        self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: bytes.max(16).next_multiple_of(16),
            usage: wgpu::BufferUsages::STORAGE
                | wgpu::BufferUsages::COPY_SRC
                | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        })
    }

    /// A uniform buffer holding `value`, which writes may replace.
    pub fn uniform<T: bytemuck::Pod>(&self, label: &str, value: &T) -> wgpu::Buffer {
        let buffer = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: size_of::<T>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        self.queue
            .write_buffer(&buffer, 0, bytemuck::bytes_of(value));
        buffer
    }

    /// The pipelines of `entries` in the WGSL `source`, whose bind group 0 holds `slots` in
    /// order.
    pub fn kernel(&self, label: &str, source: &str, slots: &[Slot], entries: &[&str]) -> Kernel {
        let module = self
            .device
            .create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some(label),
                source: wgpu::ShaderSource::Wgsl(source.into()),
            });
        let layout_entries: Vec<_> = slots
            .iter()
            .enumerate()
            .map(|(binding, slot)| wgpu::BindGroupLayoutEntry {
                binding: binding as u32,
                visibility: wgpu::ShaderStages::COMPUTE,
                ty: wgpu::BindingType::Buffer {
                    ty: match slot {
                        Slot::Uniform => wgpu::BufferBindingType::Uniform,
                        Slot::Storage => wgpu::BufferBindingType::Storage { read_only: false },
                    },
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                count: None,
            })
            .collect();
        let layout = self
            .device
            .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some(label),
                entries: &layout_entries,
            });
        let pipeline_layout = self
            .device
            .create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some(label),
                bind_group_layouts: &[Some(&layout)],
                immediate_size: 0,
            });
        let pipelines = entries
            .iter()
            .map(|entry| {
                self.device
                    .create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                        label: Some(entry),
                        layout: Some(&pipeline_layout),
                        module: &module,
                        entry_point: Some(entry),
                        compilation_options: Default::default(),
                        cache: None,
                    })
            })
            .collect();
        Kernel { layout, pipelines }
    }

    /// A bind group of `kernel`'s layout with `buffers` at slots 0, 1, ….
    pub fn bind(&self, kernel: &Kernel, buffers: &[&wgpu::Buffer]) -> wgpu::BindGroup {
        let entries: Vec<_> = buffers
            .iter()
            .enumerate()
            .map(|(binding, buffer)| wgpu::BindGroupEntry {
                binding: binding as u32,
                resource: buffer.as_entire_binding(),
            })
            .collect();
        self.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: None,
            layout: &kernel.layout,
            entries: &entries,
        })
    }

    fn wait(&self) -> Result<(), Error> {
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map(|_| ())
            .map_err(|e| gpu_error(&format!("the device {} failed: {e}", self.adapter)))
    }

    /// A command encoder.
    pub fn encoder(&self) -> wgpu::CommandEncoder {
        self.device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: None })
    }

    /// The first `bytes` bytes of `source` (a multiple of 4), copied back through a staging
    /// buffer after the commands of `encoder` run.
    pub fn read(
        &self,
        encoder: wgpu::CommandEncoder,
        source: &wgpu::Buffer,
        bytes: u64,
    ) -> Result<Vec<u8>, Error> {
        let mut read = self.read_many(encoder, &[(source, bytes)])?;
        Ok(read.pop().unwrap_or_default())
    }

    /// The first bytes of each of `sources` (buffer and byte count, a multiple of 4), copied
    /// back through one staging buffer after the commands of `encoder` run: one wait on the
    /// device for them all. The staging buffer is kept for the next read-back that fits in
    /// it (it grows to the largest so far).
    pub fn read_many(
        &self,
        mut encoder: wgpu::CommandEncoder,
        sources: &[(&wgpu::Buffer, u64)],
    ) -> Result<Vec<Vec<u8>>, Error> {
        let sizes: Vec<u64> = sources
            .iter()
            .map(|&(_, bytes)| bytes.max(4).next_multiple_of(4))
            .collect();
        let total: u64 = sizes.iter().sum();
        let kept = self.staging.lock().ok().and_then(|mut slot| slot.take());
        let staging = match kept {
            Some(buffer) if buffer.size() >= total => buffer,
            _ => self.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("read-back"),
                size: total,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
        };
        let mut offset = 0;
        for (&(source, _), &size) in sources.iter().zip(&sizes) {
            encoder.copy_buffer_to_buffer(source, 0, &staging, offset, size);
            offset += size;
        }
        self.queue.submit([encoder.finish()]);
        let mapped = Arc::new(Mutex::new(None));
        let done = Arc::clone(&mapped);
        staging.map_async(wgpu::MapMode::Read, ..total, move |result| {
            if let Ok(mut slot) = done.lock() {
                *slot = Some(result);
            }
        });
        self.wait()?;
        self.check()?;
        let result = mapped.lock().ok().and_then(|mut slot| slot.take());
        match result {
            Some(Ok(())) => {}
            other => {
                return Err(gpu_error(&format!(
                    "could not read back from the device {}: {other:?}",
                    self.adapter
                )));
            }
        }
        let parts = {
            let bytes = staging
                .get_mapped_range(..total)
                .map_err(|e| gpu_error(&format!("could not map a read-back: {e}")))?;
            let mut start = 0;
            sizes
                .iter()
                .map(|&size| {
                    let part = bytes[start as usize..(start + size) as usize].to_vec();
                    start += size;
                    part
                })
                .collect()
        };
        staging.unmap();
        if let Ok(mut slot) = self.staging.lock() {
            *slot = Some(staging);
        }
        Ok(parts)
    }
}

/// Errors, naming `what` and the limit, where `limits` bind fewer storage buffers per
/// kernel than the kernels need.
pub(crate) fn check_limits(limits: &wgpu::Limits, what: &str) -> Result<(), Error> {
    if limits.max_storage_buffers_per_shader_stage >= STORAGE_BUFFERS {
        return Ok(());
    }
    Err(unavailable(&format!(
        "{what} binds {} storage buffers per kernel (max_storage_buffers_per_shader_stage), \
         {STORAGE_BUFFERS} are needed",
        limits.max_storage_buffers_per_shader_stage
    )))
}

/// Little-endian bytes read back as f32 values.
pub(super) fn floats(bytes: &[u8]) -> Vec<f32> {
    bytes
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect()
}

/// Little-endian bytes read back as u32 values.
pub(super) fn words(bytes: &[u8]) -> Vec<u32> {
    bytes
        .chunks_exact(4)
        .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect()
}

/// Records `pipeline` over `items` threads (rounded up to whole workgroups) with `group`.
pub(super) fn dispatch(
    pass: &mut wgpu::ComputePass,
    pipeline: &wgpu::ComputePipeline,
    group: &wgpu::BindGroup,
    items: u32,
) {
    let groups = items.div_ceil(WORKGROUP).max(1);
    dispatch_groups(pass, pipeline, group, groups);
}

/// Records `pipeline` over `groups` workgroups with `group`, laid out over x and y.
pub(super) fn dispatch_groups(
    pass: &mut wgpu::ComputePass,
    pipeline: &wgpu::ComputePipeline,
    group: &wgpu::BindGroup,
    groups: u32,
) {
    let x = groups.clamp(1, MAX_GROUPS);
    pass.set_pipeline(pipeline);
    pass.set_bind_group(0, group, &[]);
    pass.dispatch_workgroups(x, groups.div_ceil(x), 1);
}

/// Runs a future to completion on this thread (wgpu's requests for an adapter and a device
/// complete without an executor on native backends).
fn block_on<F: Future>(future: F) -> F::Output {
    struct Unpark(std::thread::Thread);
    impl Wake for Unpark {
        fn wake(self: Arc<Self>) {
            self.0.unpark();
        }
    }
    let waker = Waker::from(Arc::new(Unpark(std::thread::current())));
    let mut context = TaskContext::from_waker(&waker);
    let mut future = std::pin::pin!(future);
    loop {
        match future.as_mut().poll(&mut context) {
            Poll::Ready(output) => return output,
            Poll::Pending => std::thread::park(),
        }
    }
}
