//! Adapter and device selection. Vulkan only: GL/llvmpipe reassociates float
//! math (measured, docs/design.md), which breaks the bit-match contract.

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AdapterChoice {
    /// A hardware GPU, or none.
    HardwareOnly,
    /// A hardware GPU if present, else the software adapter (lavapipe).
    AnyGpu,
}

pub struct GpuContext {
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    pub info: wgpu::AdapterInfo,
    pub limits: wgpu::Limits,
}

fn is_hardware(info: &wgpu::AdapterInfo) -> bool {
    !matches!(
        info.device_type,
        wgpu::DeviceType::Cpu | wgpu::DeviceType::Other
    )
}

impl GpuContext {
    /// Open a device, or explain why none is available.
    pub fn open(choice: AdapterChoice, profile: bool) -> Result<GpuContext, String> {
        let mut desc = wgpu::InstanceDescriptor::new_without_display_handle();
        desc.backends = wgpu::Backends::VULKAN;
        let instance = wgpu::Instance::new(desc);
        let adapters = pollster::block_on(instance.enumerate_adapters(wgpu::Backends::VULKAN));
        let hardware = adapters.iter().find(|a| is_hardware(&a.get_info()));
        let adapter = match (hardware, choice) {
            (Some(a), _) => a,
            (None, AdapterChoice::HardwareOnly) => return Err("no hardware GPU found".into()),
            (None, AdapterChoice::AnyGpu) => adapters.first().ok_or(
                "no Vulkan adapter found: install Mesa's lavapipe (package mesa-vulkan-drivers) or a GPU driver",
            )?,
        };
        let info = adapter.get_info();
        let limits = adapter.limits();
        let mut features = wgpu::Features::empty();
        if profile && adapter.features().contains(wgpu::Features::TIMESTAMP_QUERY) {
            features |= wgpu::Features::TIMESTAMP_QUERY;
        }
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("spatter"),
            required_features: features,
            required_limits: limits.clone(),
            ..Default::default()
        }))
        .map_err(|e| format!("cannot open GPU device {}: {e}", info.name))?;
        Ok(GpuContext {
            device,
            queue,
            info,
            limits,
        })
    }

    pub fn is_software(&self) -> bool {
        !is_hardware(&self.info)
    }

    pub fn describe(&self) -> String {
        let kind = if self.is_software() {
            "software adapter"
        } else {
            "hardware"
        };
        format!(
            "gpu: {} ({}, {} {})",
            self.info.name, kind, self.info.driver, self.info.driver_info
        )
    }
}
