//! Named buffers and images from gpu-allocator, staging upload and readback.
//! Every allocation is named and counted so summaries can report memory per buffer.
use super::Context;
use crate::error::{Error, Result, VkContext};
use ash::vk;
use gpu_allocator::vulkan::{Allocation, AllocationCreateDesc, AllocationScheme};
pub use gpu_allocator::MemoryLocation;

/// A GPU buffer. Destroy it with `Context::destroy_buffer`.
pub struct Buffer {
    pub raw: vk::Buffer,
    /// Requested size in bytes (the Vulkan buffer is at least 16 bytes).
    pub size: u64,
    pub name: String,
    alloc: Option<Allocation>,
}

impl Buffer {
    /// Mapped bytes, for host-visible buffers.
    pub fn mapped(&self) -> Option<&[u8]> {
        let a = self.alloc.as_ref()?;
        a.mapped_slice().map(|s| &s[..self.size as usize])
    }

    pub fn mapped_mut(&mut self) -> Option<&mut [u8]> {
        let size = self.size as usize;
        let a = self.alloc.as_mut()?;
        a.mapped_slice_mut().map(|s| &mut s[..size])
    }

    /// Descriptor for the whole buffer.
    pub fn info(&self) -> vk::DescriptorBufferInfo {
        vk::DescriptorBufferInfo {
            buffer: self.raw,
            offset: 0,
            range: vk::WHOLE_SIZE,
        }
    }
}

/// A 2D GPU image with one view. Destroy it with `Context::destroy_image`.
pub struct Image {
    pub raw: vk::Image,
    pub view: vk::ImageView,
    pub format: vk::Format,
    pub width: u32,
    pub height: u32,
    pub name: String,
    alloc: Option<Allocation>,
}

const STORAGE: vk::BufferUsageFlags = vk::BufferUsageFlags::from_raw(
    vk::BufferUsageFlags::STORAGE_BUFFER.as_raw()
        | vk::BufferUsageFlags::TRANSFER_SRC.as_raw()
        | vk::BufferUsageFlags::TRANSFER_DST.as_raw(),
);

impl Context {
    /// A device-local storage buffer (also a transfer source and destination).
    pub fn storage_buffer(&self, name: &str, size: u64) -> Result<Buffer> {
        self.create_buffer(name, size, STORAGE, MemoryLocation::GpuOnly)
    }

    /// A storage buffer that also holds indirect-dispatch or draw arguments.
    pub fn indirect_buffer(&self, name: &str, size: u64) -> Result<Buffer> {
        self.create_buffer(
            name,
            size,
            STORAGE | vk::BufferUsageFlags::INDIRECT_BUFFER,
            MemoryLocation::GpuOnly,
        )
    }

    pub fn create_buffer(
        &self,
        name: &str,
        size: u64,
        usage: vk::BufferUsageFlags,
        location: MemoryLocation,
    ) -> Result<Buffer> {
        let info = vk::BufferCreateInfo::default()
            .size(size.max(16))
            .usage(usage)
            .sharing_mode(vk::SharingMode::EXCLUSIVE);
        let raw = unsafe { self.device.create_buffer(&info, None) }
            .ctx(&format!("create buffer '{name}' ({size} bytes)"))?;
        let req = unsafe { self.device.get_buffer_memory_requirements(raw) };
        let alloc = self.allocator().allocate(&AllocationCreateDesc {
            name,
            requirements: req,
            location,
            linear: true,
            allocation_scheme: AllocationScheme::GpuAllocatorManaged,
        });
        let alloc = match alloc {
            Ok(a) => a,
            Err(e) => {
                unsafe { self.device.destroy_buffer(raw, None) };
                return Err(Error::Memory(format!(
                    "cannot allocate buffer '{name}' ({size} bytes): {e}"
                )));
            }
        };
        if let Err(e) = unsafe {
            self.device
                .bind_buffer_memory(raw, alloc.memory(), alloc.offset())
        } {
            let _ = self.allocator().free(alloc);
            unsafe { self.device.destroy_buffer(raw, None) };
            return Err(e).ctx(&format!("bind buffer '{name}'"));
        }
        self.set_name(raw, name);
        *self
            .memory
            .lock()
            .unwrap()
            .entry(name.to_string())
            .or_default() += req.size;
        self.count_object("buffer", 1);
        Ok(Buffer {
            raw,
            size,
            name: name.to_string(),
            alloc: Some(alloc),
        })
    }

    pub fn destroy_buffer(&self, b: &mut Buffer) {
        if let Some(a) = b.alloc.take() {
            self.forget(&b.name, a.size());
            self.count_object("buffer", -1);
            let _ = self.allocator().free(a);
            unsafe { self.device.destroy_buffer(b.raw, None) };
            b.raw = vk::Buffer::null();
        }
    }

    fn forget(&self, name: &str, bytes: u64) {
        let mut m = self.memory.lock().unwrap();
        if let Some(v) = m.get_mut(name) {
            *v = v.saturating_sub(bytes);
            if *v == 0 {
                m.remove(name);
            }
        }
    }

    /// Copy `data` into `dst` at byte `offset` (directly if mapped, else via staging).
    pub fn upload<T: bytemuck::Pod>(
        &self,
        dst: &mut Buffer,
        offset: u64,
        data: &[T],
    ) -> Result<()> {
        let bytes: &[u8] = bytemuck::cast_slice(data);
        if bytes.is_empty() {
            return Ok(());
        }
        let end = offset + bytes.len() as u64;
        if end > dst.size {
            return Err(Error::Param(format!(
                "upload of {} bytes at {offset} overflows buffer '{}' ({} bytes)",
                bytes.len(),
                dst.name,
                dst.size
            )));
        }
        if let Some(m) = dst.mapped_mut() {
            m[offset as usize..end as usize].copy_from_slice(bytes);
            return Ok(());
        }
        let mut staging = self.create_buffer(
            "staging upload",
            bytes.len() as u64,
            vk::BufferUsageFlags::TRANSFER_SRC,
            MemoryLocation::CpuToGpu,
        )?;
        staging
            .mapped_mut()
            .expect("staging is mapped")
            .copy_from_slice(bytes);
        let region = vk::BufferCopy {
            src_offset: 0,
            dst_offset: offset,
            size: bytes.len() as u64,
        };
        let r = self.one_shot(|cmd| unsafe {
            self.device
                .cmd_copy_buffer(cmd, staging.raw, dst.raw, &[region]);
        });
        self.destroy_buffer(&mut staging);
        r
    }

    /// Read `count` elements of T from `src` at byte `offset`.
    pub fn readback<T: bytemuck::Pod>(
        &self,
        src: &Buffer,
        offset: u64,
        count: usize,
    ) -> Result<Vec<T>> {
        let len = (count * std::mem::size_of::<T>()) as u64;
        if offset + len > src.size {
            return Err(Error::Param(format!(
                "readback of {len} bytes at {offset} overruns buffer '{}' ({} bytes)",
                src.name, src.size
            )));
        }
        let mut out = vec![T::zeroed(); count];
        if len == 0 {
            return Ok(out);
        }
        let mut staging = self.create_buffer(
            "staging readback",
            len,
            vk::BufferUsageFlags::TRANSFER_DST,
            MemoryLocation::GpuToCpu,
        )?;
        let region = vk::BufferCopy {
            src_offset: offset,
            dst_offset: 0,
            size: len,
        };
        let r = self.one_shot(|cmd| {
            // The writes of earlier submissions -> this copy.
            let writes = super::sync::COMPUTE_WRITE
                | super::sync::TRANSFER_WRITE
                | super::sync::FRAGMENT_WRITE;
            self.barrier(cmd, writes, super::sync::TRANSFER_READ);
            unsafe {
                self.device
                    .cmd_copy_buffer(cmd, src.raw, staging.raw, &[region])
            };
        });
        if r.is_ok() {
            let m = staging.mapped().expect("staging is mapped");
            bytemuck::cast_slice_mut::<T, u8>(&mut out).copy_from_slice(m);
        }
        self.destroy_buffer(&mut staging);
        r.map(|_| out)
    }

    /// Whole buffer as `Vec<T>`.
    pub fn read_all<T: bytemuck::Pod>(&self, src: &Buffer) -> Result<Vec<T>> {
        self.readback(src, 0, src.size as usize / std::mem::size_of::<T>())
    }

    /// Long because each step (image, memory, bind, view) releases what the earlier steps
    /// made when it fails.
    pub fn create_image(
        &self,
        name: &str,
        width: u32,
        height: u32,
        format: vk::Format,
        usage: vk::ImageUsageFlags,
    ) -> Result<Image> {
        let max = self.limits.max_image_dimension2_d;
        if width == 0 || height == 0 || width > max || height > max {
            return Err(Error::Param(format!(
                "image '{name}' of {width}x{height}: each side must be 1..={max} on this device"
            )));
        }
        let info = vk::ImageCreateInfo::default()
            .image_type(vk::ImageType::TYPE_2D)
            .format(format)
            .extent(vk::Extent3D {
                width,
                height,
                depth: 1,
            })
            .mip_levels(1)
            .array_layers(1)
            .samples(vk::SampleCountFlags::TYPE_1)
            .tiling(vk::ImageTiling::OPTIMAL)
            .usage(usage)
            .initial_layout(vk::ImageLayout::UNDEFINED);
        let raw = unsafe { self.device.create_image(&info, None) }
            .ctx(&format!("create image '{name}'"))?;
        let req = unsafe { self.device.get_image_memory_requirements(raw) };
        let alloc = match self.allocator().allocate(&AllocationCreateDesc {
            name,
            requirements: req,
            location: MemoryLocation::GpuOnly,
            linear: false,
            allocation_scheme: AllocationScheme::GpuAllocatorManaged,
        }) {
            Ok(a) => a,
            Err(e) => {
                unsafe { self.device.destroy_image(raw, None) };
                return Err(Error::Memory(format!(
                    "cannot allocate image '{name}': {e}"
                )));
            }
        };
        // A failed bind or view releases the image and its memory.
        let release = |alloc| {
            let _ = self.allocator().free(alloc);
            unsafe { self.device.destroy_image(raw, None) };
        };
        if let Err(e) = unsafe {
            self.device
                .bind_image_memory(raw, alloc.memory(), alloc.offset())
        } {
            release(alloc);
            return Err(e).ctx(&format!("bind image '{name}'"));
        }
        let aspect = if format == vk::Format::D32_SFLOAT {
            vk::ImageAspectFlags::DEPTH
        } else {
            vk::ImageAspectFlags::COLOR
        };
        let view_info = vk::ImageViewCreateInfo::default()
            .image(raw)
            .view_type(vk::ImageViewType::TYPE_2D)
            .format(format)
            .subresource_range(subresource(aspect));
        let view = match unsafe { self.device.create_image_view(&view_info, None) } {
            Ok(v) => v,
            Err(e) => {
                release(alloc);
                return Err(e).ctx(&format!("create view of '{name}'"));
            }
        };
        self.set_name(raw, name);
        self.count_object("image", 1);
        self.set_name(view, &format!("{name} view"));
        *self
            .memory
            .lock()
            .unwrap()
            .entry(name.to_string())
            .or_default() += req.size;
        Ok(Image {
            raw,
            view,
            format,
            width,
            height,
            name: name.to_string(),
            alloc: Some(alloc),
        })
    }

    pub fn destroy_image(&self, img: &mut Image) {
        if let Some(a) = img.alloc.take() {
            self.forget(&img.name, a.size());
            self.count_object("image", -1);
            let _ = self.allocator().free(a);
            unsafe {
                self.device.destroy_image_view(img.view, None);
                self.device.destroy_image(img.raw, None);
            }
        }
    }
}

pub fn subresource(aspect: vk::ImageAspectFlags) -> vk::ImageSubresourceRange {
    vk::ImageSubresourceRange {
        aspect_mask: aspect,
        base_mip_level: 0,
        level_count: 1,
        base_array_layer: 0,
        layer_count: 1,
    }
}
