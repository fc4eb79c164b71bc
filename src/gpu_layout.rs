//! Structs shared with WGSL: `gpu_struct!` declares a `#[repr(C)]` struct of f32,
//! u32, 4-vectors, arrays and other such structs, and records every member's name,
//! offset and type, so a test (tests/params_layout.rs) can hold the Rust struct
//! against its WGSL twin as naga lays it out. A member renamed, retyped or moved on
//! one side only then fails that test instead of feeding a pass the wrong number.

/// What a member is, as both languages see it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum GpuType {
    F32,
    U32,
    /// vec4<f32>, `[f32; 4]` in Rust.
    Vec4F32,
    /// vec4<u32>, `[u32; 4]` in Rust.
    Vec4U32,
    /// A struct (its WGSL name and members).
    Struct(&'static str, Vec<Member>),
    /// A fixed-size array: element type, length, stride in bytes.
    Array(Box<GpuType>, usize, usize),
}

#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Member {
    pub name: &'static str,
    pub offset: usize,
    pub ty: GpuType,
}

/// A type that can be a member of a `gpu_struct!`.
pub trait GpuLayout {
    fn gpu_type() -> GpuType;
}

/// Implemented by `gpu_struct!` only: the element types arrays may hold.
pub trait GpuStruct: GpuLayout {}

impl GpuLayout for f32 {
    fn gpu_type() -> GpuType {
        GpuType::F32
    }
}
impl GpuLayout for u32 {
    fn gpu_type() -> GpuType {
        GpuType::U32
    }
}
impl GpuLayout for [f32; 4] {
    fn gpu_type() -> GpuType {
        GpuType::Vec4F32
    }
}
impl GpuLayout for [u32; 4] {
    fn gpu_type() -> GpuType {
        GpuType::Vec4U32
    }
}
impl<T: GpuStruct, const N: usize> GpuLayout for [T; N] {
    fn gpu_type() -> GpuType {
        GpuType::Array(Box::new(T::gpu_type()), N, std::mem::size_of::<T>())
    }
}

/// Flattened `path offset type` lines, one per scalar or vector, with array
/// elements as `name[]` (the first element's offsets) plus a line for the array's
/// length and stride. Both sides of the layout check print this.
pub fn flatten(ty: &GpuType) -> Vec<String> {
    let mut out = Vec::new();
    walk(ty, "", 0, &mut out);
    out
}

fn walk(ty: &GpuType, path: &str, base: usize, out: &mut Vec<String>) {
    match ty {
        GpuType::Struct(_, members) => {
            for m in members {
                let p = if path.is_empty() {
                    m.name.to_string()
                } else {
                    format!("{path}.{}", m.name)
                };
                walk(&m.ty, &p, base + m.offset, out);
            }
        }
        GpuType::Array(elem, len, stride) => {
            out.push(format!("{path} @{base} array len {len} stride {stride}"));
            walk(elem, &format!("{path}[]"), base, out);
        }
        other => out.push(format!("{path} @{base} {other:?}")),
    }
}

/// Declares a struct shared with WGSL (same name, same members in the same order).
macro_rules! gpu_struct {
    ($(#[$meta:meta])* pub struct $name:ident {
        $($(#[$fmeta:meta])* pub $field:ident : $ty:ty,)*
    }) => {
        $(#[$meta])*
        #[repr(C)]
        #[derive(Debug, Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
        pub struct $name {
            $($(#[$fmeta])* pub $field: $ty,)*
        }
        impl $crate::gpu_layout::GpuLayout for $name {
            fn gpu_type() -> $crate::gpu_layout::GpuType {
                $crate::gpu_layout::GpuType::Struct(stringify!($name), vec![
                    $($crate::gpu_layout::Member {
                        name: stringify!($field),
                        offset: std::mem::offset_of!($name, $field),
                        ty: <$ty as $crate::gpu_layout::GpuLayout>::gpu_type(),
                    },)*
                ])
            }
        }
        impl $crate::gpu_layout::GpuStruct for $name {}
    };
}
pub(crate) use gpu_struct;
