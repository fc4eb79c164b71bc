//! Structs shared with WGSL: `gpu_struct!` declares a struct of f32, u32, 4-vectors
//! (`glam::Vec4`, `glam::UVec4`), arrays and other such structs. `encase::ShaderType`
//! (derived) lays it out by WGSL's rules, member alignment, struct size and array
//! stride included, so the padding is not written by hand; the uniform address
//! space's extra constraints (a struct member at a multiple of 16 and 16 bytes
//! past a preceding struct, array strides of 16) are stated as
//! `#[shader(align(16))]` on the member, the twin of WGSL's `@align(16)`, and
//! checked by encase on every write (`assert_uniform_compat`).
//!
//! The macro also records every member's name and type in order and gives a
//! visitor over every scalar, so a test (tests/params_layout.rs) can hold the
//! Rust struct against its WGSL twin as naga lays it out: the same members in the
//! same order, and each value encase writes found at the offset naga gives it. A
//! member renamed, retyped or moved on one side only then fails that test instead
//! of feeding a pass the wrong number.

/// What a member is, as both languages see it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum GpuType {
    F32,
    U32,
    /// vec4<f32>, `glam::Vec4` in Rust.
    Vec4F32,
    /// vec4<u32>, `glam::UVec4` in Rust.
    Vec4U32,
    /// A struct (its WGSL name and members, in order).
    Struct(&'static str, Vec<Member>),
    /// A fixed-size array: element type and length (the stride is encase's and
    /// naga's business; the layout test probes every element).
    Array(Box<GpuType>, usize),
}

#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Member {
    pub name: &'static str,
    pub ty: GpuType,
}

/// A type that can be a member of a `gpu_struct!`.
pub trait GpuLayout {
    fn gpu_type() -> GpuType;
    /// Calls `f` with every scalar-or-vector leaf below `self` as its 4-byte
    /// words (1 or 4), under the path `flatten` prints, array elements as
    /// `name[k]`: the layout test writes a distinct value into each word.
    fn visit_words(&mut self, path: &str, f: &mut dyn FnMut(&str, &mut [u32]));
}

/// Implemented by `gpu_struct!` only: the element types arrays may hold.
pub trait GpuStruct: GpuLayout {}

impl GpuLayout for f32 {
    fn gpu_type() -> GpuType {
        GpuType::F32
    }
    fn visit_words(&mut self, path: &str, f: &mut dyn FnMut(&str, &mut [u32])) {
        f(path, std::slice::from_mut(bytemuck::cast_mut(self)))
    }
}
impl GpuLayout for u32 {
    fn gpu_type() -> GpuType {
        GpuType::U32
    }
    fn visit_words(&mut self, path: &str, f: &mut dyn FnMut(&str, &mut [u32])) {
        f(path, std::slice::from_mut(self))
    }
}
impl GpuLayout for glam::Vec4 {
    fn gpu_type() -> GpuType {
        GpuType::Vec4F32
    }
    fn visit_words(&mut self, path: &str, f: &mut dyn FnMut(&str, &mut [u32])) {
        let words: &mut [u32; 4] = bytemuck::cast_mut(AsMut::<[f32; 4]>::as_mut(self));
        f(path, words)
    }
}
impl GpuLayout for glam::UVec4 {
    fn gpu_type() -> GpuType {
        GpuType::Vec4U32
    }
    fn visit_words(&mut self, path: &str, f: &mut dyn FnMut(&str, &mut [u32])) {
        f(path, AsMut::<[u32; 4]>::as_mut(self))
    }
}
impl<T: GpuStruct, const N: usize> GpuLayout for [T; N] {
    fn gpu_type() -> GpuType {
        GpuType::Array(Box::new(T::gpu_type()), N)
    }
    fn visit_words(&mut self, path: &str, f: &mut dyn FnMut(&str, &mut [u32])) {
        for (k, e) in self.iter_mut().enumerate() {
            e.visit_words(&format!("{path}[{k}]"), f);
        }
    }
}

/// `path.name`, or `name` at the top.
pub fn join(path: &str, name: &str) -> String {
    if path.is_empty() {
        name.to_string()
    } else {
        format!("{path}.{name}")
    }
}

/// Flattened `path type` lines, one per scalar or vector in declaration order,
/// with array elements as `name[]` (one element's members) after a line for the
/// array's length. Both sides of the layout check print this.
pub fn flatten(ty: &GpuType) -> Vec<String> {
    let mut out = Vec::new();
    walk(ty, "", &mut out);
    out
}

fn walk(ty: &GpuType, path: &str, out: &mut Vec<String>) {
    match ty {
        GpuType::Struct(_, members) => {
            for m in members {
                walk(&m.ty, &join(path, m.name), out);
            }
        }
        GpuType::Array(elem, len) => {
            out.push(format!("{path} array len {len}"));
            walk(elem, &format!("{path}[]"), out);
        }
        other => out.push(format!("{path} {other:?}")),
    }
}

/// Declares a struct shared with WGSL (same name, same members in the same order).
/// A member may carry `#[shader(align(N))]` / `#[shader(size(N))]`, encase's twins
/// of WGSL's `@align(N)` / `@size(N)`.
macro_rules! gpu_struct {
    ($(#[$meta:meta])* pub struct $name:ident {
        $($(#[$fmeta:meta])* pub $field:ident : $ty:ty,)*
    }) => {
        $(#[$meta])*
        #[derive(Debug, Clone, Copy, bytemuck::Zeroable, encase::ShaderType)]
        pub struct $name {
            $($(#[$fmeta])* pub $field: $ty,)*
        }
        impl $crate::gpu_layout::GpuLayout for $name {
            fn gpu_type() -> $crate::gpu_layout::GpuType {
                $crate::gpu_layout::GpuType::Struct(stringify!($name), vec![
                    $($crate::gpu_layout::Member {
                        name: stringify!($field),
                        ty: <$ty as $crate::gpu_layout::GpuLayout>::gpu_type(),
                    },)*
                ])
            }
            fn visit_words(&mut self, path: &str, f: &mut dyn FnMut(&str, &mut [u32])) {
                $(<$ty as $crate::gpu_layout::GpuLayout>::visit_words(
                    &mut self.$field,
                    &$crate::gpu_layout::join(path, stringify!($field)),
                    f,
                );)*
            }
        }
        impl $crate::gpu_layout::GpuStruct for $name {}
    };
}
pub(crate) use gpu_struct;
