//! The structs and constants the kernels share with the host, each declared once, in
//! Rust, from which their WGSL is generated.
//!
//! A struct is declared with `gpu_struct!`: doc comments, fields with their Rust type
//! and, where a Rust type stands for more than one WGSL type, the WGSL one (`[f32; 3] as
//! "vec3<f32>"`, with the padding after it written out as a field). The macro gives the
//! `#[repr(C)]` Pod struct the host uploads, its field list ([`GpuStruct::fields`]: name,
//! offset, size, WGSL type, doc) and so its WGSL declaration ([`StructDeclaration::wgsl`]).
//! A constant is declared with `gpu_constants!`. Each `*_types.rs` module of this crate
//! gathers its structs and constants into one generated WGSL module ([`GpuModule`]) with
//! a path under `gpu/` (`gpu/restir.wgsl`): no such file exists; a WGSL file names it in
//! its `// #import` lines like any other file, and [`crate::wgsl_files::wgsl_file`]
//! gives its generated text. So the WGSL, the Rust struct, `strata.h` and the shader
//! includes of the export package all come from one declaration, and a new field is one
//! line of Rust.
//!
//! Why Rust is the source and not WGSL: generating Rust from WGSL would take naga as a
//! build dependency, compiled a second time in every build, and generated Rust types lose
//! their doc comments for rustdoc and IDEs; the C header and the shader includes were
//! already written from the Rust side. What the macro cannot know is whether the layout
//! it promises holds: naga's layout of the generated WGSL is compared with the Rust
//! offsets and sizes of every declared struct by one test (`crate::layout`).

use std::borrow::Cow;

/// A Rust type with a WGSL type of the same size and layout by default: the scalars, arrays
/// of them, and the structs of `gpu_struct!` (by their WGSL name). Vectors are not a
/// default: `[f32; 3]` is `vec3<f32>` or `array<f32, 3>`, which lay out differently, so a
/// field says `as "vec3<f32>"`.
pub trait WgslType {
    /// The WGSL type.
    fn wgsl_type() -> Cow<'static, str>;
}

impl WgslType for u32 {
    fn wgsl_type() -> Cow<'static, str> {
        Cow::Borrowed("u32")
    }
}

impl WgslType for i32 {
    fn wgsl_type() -> Cow<'static, str> {
        Cow::Borrowed("i32")
    }
}

impl WgslType for f32 {
    fn wgsl_type() -> Cow<'static, str> {
        Cow::Borrowed("f32")
    }
}

impl<T: WgslType, const N: usize> WgslType for [T; N] {
    fn wgsl_type() -> Cow<'static, str> {
        Cow::Owned(format!("array<{}, {N}>", T::wgsl_type()))
    }
}

/// One field of a [`GpuStruct`].
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct GpuField {
    /// The field's name, the same in Rust and WGSL.
    pub name: &'static str,
    /// Its byte offset in the Rust struct.
    pub offset: usize,
    /// Its byte size in the Rust struct.
    pub size: usize,
    /// Its WGSL type (`u32`, `vec3<f32>`, `array<u32, 4>`, `PathCandidate`).
    pub wgsl_type: Cow<'static, str>,
    /// Its Rust type as declared (`[f32; 3]`), for the layout test to compare the scalar
    /// a WGSL type given by hand holds with the Rust one's.
    pub rust_type: &'static str,
    /// Its doc comment, one line per `///` line.
    pub doc: &'static str,
}

/// A struct declared with `gpu_struct!`: a Pod Rust struct with a WGSL twin generated
/// from the same declaration.
pub trait GpuStruct: bytemuck::Pod + WgslType {
    /// The WGSL struct's name (the Rust name unless declared `as "Name"`).
    const WGSL_NAME: &'static str;
    /// The struct's doc comment, one line per `///` line.
    const DOC: &'static str;
    /// The fields in declaration order.
    fn fields() -> Vec<GpuField>;
}

/// A [`GpuStruct`] as data, so that one list holds structs of different types.
#[derive(Clone, Debug)]
pub struct StructDeclaration {
    /// The WGSL name.
    pub name: &'static str,
    /// The doc comment.
    pub doc: &'static str,
    /// The Rust struct's size in bytes.
    pub size: usize,
    /// The fields in declaration order.
    pub fields: Vec<GpuField>,
}

impl StructDeclaration {
    /// The declaration of `T`.
    pub fn of<T: GpuStruct>() -> StructDeclaration {
        StructDeclaration { name: T::WGSL_NAME, doc: T::DOC, size: size_of::<T>(), fields: T::fields() }
    }

    /// The WGSL declaration, with the docs as comments.
    pub fn wgsl(&self) -> String {
        let mut text = wgsl_comment(self.doc, "");
        text += &format!("struct {} {{\n", self.name);
        for field in &self.fields {
            text += &wgsl_comment(field.doc, "    ");
            text += &format!("    {}: {},\n", field.name, field.wgsl_type);
        }
        text += "}\n";
        text
    }
}

/// A constant declared with `gpu_constants!`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GpuConstant {
    /// The WGSL name (and C's, after `STRATA_`): the Rust name unless the declaration
    /// gives one (`pub const TILE_SIZE: u32 as "BLUE_NOISE_TILE" = 128;`), for a Rust name
    /// that its module's path already qualifies.
    pub name: &'static str,
    /// The value.
    pub value: ConstantValue,
    /// The doc comment.
    pub doc: &'static str,
}

impl GpuConstant {
    /// The WGSL declaration, with the doc as a comment. An `f32` is written with the
    /// fewest digits that read back as the same value, and the `f` suffix so that WGSL
    /// reads it as an `f32` directly.
    pub fn wgsl(&self) -> String {
        let (ty, value) = match self.value {
            ConstantValue::U32(v) => ("u32", format!("{v}u")),
            ConstantValue::F32(v) => ("f32", format!("{v:?}f")),
        };
        format!("{}const {}: {ty} = {value};\n", wgsl_comment(self.doc, ""), self.name)
    }
}

/// A constant's value, as WGSL types it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ConstantValue {
    /// `u32`.
    U32(u32),
    /// `f32` (compared bit for bit).
    F32(f32),
}

impl From<u32> for ConstantValue {
    fn from(value: u32) -> Self {
        ConstantValue::U32(value)
    }
}

impl From<f32> for ConstantValue {
    fn from(value: f32) -> Self {
        ConstantValue::F32(value)
    }
}

/// The generated WGSL module of one `*_types.rs` module: its constants and structs.
#[derive(Clone, Debug)]
pub struct GpuModule {
    /// The path WGSL files import it by (`gpu/restir.wgsl`).
    pub path: &'static str,
    /// The Rust file that declares it, named in the module's first line.
    pub source: &'static str,
    /// Its constants.
    pub constants: Vec<GpuConstant>,
    /// Its structs, each after the structs its fields use.
    pub structs: Vec<StructDeclaration>,
    /// Functions that read structs (of this module or those it imports) out of an array of
    /// 16-byte rows: a module of readers names the function that reads a row in a
    /// `// #requires` line and the structs' modules in `// #import` lines ([`RowReaders`]).
    pub readers: Option<RowReaders>,
}

/// Readers of structs packed in one array of 16-byte rows, generated from the structs'
/// declarations, for kernels that bind several arrays of records as one buffer (WebGPU
/// allows a stage 8 to 10 storage buffers). Each struct is laid out in its rows exactly as
/// in its own array (the Rust layout; a struct read this way must be a whole number of
/// rows, which [`RowReaders::wgsl`] checks), so the host appends each array's bytes as
/// they are. The readers take each row from a function the including kernel defines
/// (`render/scene.wgsl`'s `scene_row` reads a storage buffer or, for a small scene, a
/// uniform one).
#[derive(Clone, Debug)]
pub struct RowReaders {
    /// The name of the required function, `fn NAME(row: u32) -> vec4<u32>`
    /// ([`Self::declaration`]): row `row` of the records' array.
    pub row_function: &'static str,
    /// The generated modules that declare the structs (`gpu/render.wgsl`).
    pub imports: Vec<&'static str>,
    /// The structs read.
    pub structs: Vec<StructDeclaration>,
}

impl RowReaders {
    /// The row function's signature, as its `// #requires` line and the including kernel
    /// write it.
    pub fn declaration(&self) -> String {
        format!("fn {}(row: u32) -> vec4<u32>", self.row_function)
    }

    /// The module's directive lines and one function per struct:
    /// `fn read_<snake name>(first_row: u32, index: u32) -> Name` reads record `index` of
    /// the section that starts at row `first_row`.
    pub fn wgsl(&self) -> String {
        let mut text = String::new();
        for import in &self.imports {
            text += &format!("// #import {import}\n");
        }
        text += &format!("// #requires {}\n", self.declaration());
        for declaration in &self.structs {
            text += "\n";
            text += &row_reader(declaration, self.row_function);
        }
        text
    }
}

/// The WGSL reader of `declaration` through the row function `row_function` (see
/// [`RowReaders::wgsl`]). Every field is a scalar or vector of `u32`, `i32` or `f32` within
/// one row; a declaration that has another (an array, a struct, a vector across rows)
/// cannot be packed this way, and the panic names it (the module tests generate every
/// reader, so that cannot reach a user).
fn row_reader(declaration: &StructDeclaration, row_function: &str) -> String {
    assert!(
        declaration.size.is_multiple_of(16),
        "struct {} is {} bytes, not a whole number of rows",
        declaration.name,
        declaration.size
    );
    let rows = declaration.size / 16;
    let mut text = format!(
        "// The {name} at `index` of the section of the rows that starts at row `first_row` ({rows} row{s} each).\n\
         fn read_{snake}(first_row: u32, index: u32) -> {name} {{\n    let row = first_row + index * {rows}u;\n",
        name = declaration.name,
        snake = snake_case(declaration.name),
        s = if rows == 1 { "" } else { "s" },
    );
    for row in 0..rows {
        let at = if row == 0 { String::new() } else { format!(" + {row}u") };
        text += &format!("    let r{row} = {row_function}(row{at});\n");
    }
    let fields: Vec<String> = declaration.fields.iter().map(|field| field_from_row(declaration.name, field)).collect();
    text += &format!("    return {}({});\n}}\n", declaration.name, fields.join(", "));
    text
}

/// The expression of `field` read from its row variable (`r1.yzw`, `bitcast<f32>(r0.w)`).
fn field_from_row(name: &str, field: &GpuField) -> String {
    let unreadable =
        || panic!("field `{}` of {name} ({}) cannot be read from 16-byte rows", field.name, field.wgsl_type);
    let (width, scalar) = match field.wgsl_type.as_ref() {
        scalar @ ("u32" | "i32" | "f32") => (1, scalar),
        vector => {
            let Some((width, scalar)) = vector
                .strip_prefix("vec")
                .and_then(|rest| rest.split_once('<'))
                .and_then(|(width, scalar)| Some((width.parse::<usize>().ok()?, scalar.strip_suffix('>')?)))
            else {
                unreadable()
            };
            (width, scalar)
        }
    };
    let lane = field.offset % 16 / 4;
    if !matches!(scalar, "u32" | "i32" | "f32") || !field.offset.is_multiple_of(4) || lane + width > 4 {
        unreadable();
    }
    let words = format!("r{}.{}", field.offset / 16, &"xyzw"[lane..lane + width]);
    match (scalar, width) {
        ("u32", _) => words,
        (_, 1) => format!("bitcast<{scalar}>({words})"),
        _ => format!("bitcast<vec{width}<{scalar}>>({words})"),
    }
}

/// `TriangleInfo` → `triangle_info`.
fn snake_case(name: &str) -> String {
    let mut snake = String::new();
    for (i, c) in name.chars().enumerate() {
        if c.is_uppercase() && i > 0 {
            snake.push('_');
        }
        snake.push(c.to_ascii_lowercase());
    }
    snake
}

impl GpuModule {
    /// The module's WGSL text.
    pub fn wgsl(&self) -> String {
        let mut text = format!(
            "// {}: generated by strata-kernels from {} (strata_kernels::gpu); not a file.\n",
            self.path, self.source
        );
        for constant in &self.constants {
            text += "\n";
            text += &constant.wgsl();
        }
        for declaration in &self.structs {
            text += "\n";
            text += &declaration.wgsl();
        }
        if let Some(readers) = &self.readers {
            text += &readers.wgsl();
        }
        text
    }
}

/// `doc` (lines of a doc comment) as `//` lines indented by `indent`; Rust's intra-doc
/// links lose their brackets.
fn wgsl_comment(doc: &str, indent: &str) -> String {
    doc.lines()
        .map(|line| {
            let line = line.strip_prefix(' ').unwrap_or(line).replace("[`", "`").replace("`]", "`");
            if line.is_empty() { format!("{indent}//\n") } else { format!("{indent}// {line}\n") }
        })
        .collect()
}

/// Declares a struct shared with the kernels, once: the `#[repr(C)]` Pod Rust struct
/// (deriving `Clone, Copy, Debug, Default, PartialEq`, Pod and Zeroable, and what an
/// optional `#[derive(...)]` after the doc comment adds) and its [`GpuStruct`]
/// implementation, from which its WGSL is generated.
///
/// ```ignore
/// gpu_struct! {
///     /// Doc comment (also the WGSL's comment).
///     #[derive(Eq, Hash)]
///     pub struct Name as "WgslName" {
///         /// A field.
///         pub count: u32,
///         /// A vector: the WGSL type is said where the Rust type does not decide it.
///         pub position: [f32; 3] as "vec3<f32>",
///         /// The padding WGSL puts after a vec3 before a 16-byte aligned field.
///         pub _pad: u32,
///     }
/// }
/// ```
macro_rules! gpu_struct {
    (
        $(#[doc = $doc:literal])*
        $(#[derive($($derive:ident),* $(,)?)])?
        pub struct $name:ident $(as $wgsl_name:literal)? {
            $(
                $(#[doc = $field_doc:literal])*
                pub $field:ident : $ty:ty $(as $wgsl_type:literal)?
            ),* $(,)?
        }
    ) => {
        $(#[doc = $doc])*
        #[repr(C)]
        #[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable $($(, $derive)*)?)]
        pub struct $name {
            $(
                $(#[doc = $field_doc])*
                pub $field: $ty,
            )*
        }

        impl $crate::gpu::WgslType for $name {
            fn wgsl_type() -> std::borrow::Cow<'static, str> {
                std::borrow::Cow::Borrowed(<$name as $crate::gpu::GpuStruct>::WGSL_NAME)
            }
        }

        impl $crate::gpu::GpuStruct for $name {
            const WGSL_NAME: &'static str = gpu_struct!(@first $($wgsl_name,)? stringify!($name));
            const DOC: &'static str = concat!($($doc, "\n"),*);
            fn fields() -> Vec<$crate::gpu::GpuField> {
                vec![$(
                    $crate::gpu::GpuField {
                        name: stringify!($field),
                        offset: core::mem::offset_of!($name, $field),
                        size: size_of::<$ty>(),
                        wgsl_type: gpu_struct!(@wgsl $ty $(, $wgsl_type)?),
                        rust_type: stringify!($ty),
                        doc: concat!($($field_doc, "\n"),*),
                    }
                ),*]
            }
        }
    };
    (@first $first:expr $(, $rest:expr)*) => {
        $first
    };
    (@wgsl $ty:ty) => {
        <$ty as $crate::gpu::WgslType>::wgsl_type()
    };
    (@wgsl $ty:ty, $wgsl:literal) => {
        std::borrow::Cow::Borrowed($wgsl)
    };
}
pub(crate) use gpu_struct;

/// Declares constants shared with the kernels, once: each a Rust `pub const` (`u32` or
/// `f32`) and a [`GpuConstant`] of the list function named first (with its visibility),
/// from which its WGSL is generated. A constant may give its WGSL name after its type.
///
/// ```ignore
/// gpu_constants! {
///     pub(crate) fn constants;
///     /// Doc comment (also the WGSL's comment).
///     pub const NO_LIGHT: u32 = u32::MAX;
///     /// Side of the tile, `BLUE_NOISE_TILE` in WGSL.
///     pub const TILE_SIZE: u32 as "BLUE_NOISE_TILE" = 128;
/// }
/// ```
macro_rules! gpu_constants {
    (
        $vis:vis fn $list:ident;
        $(
            $(#[doc = $doc:literal])*
            pub const $name:ident : $ty:ty $(as $wgsl:literal)? = $value:expr;
        )*
    ) => {
        $(
            $(#[doc = $doc])*
            pub const $name: $ty = $value;
        )*

        /// The constants above, for the generated WGSL module.
        $vis fn $list() -> Vec<$crate::gpu::GpuConstant> {
            vec![$(
                $crate::gpu::GpuConstant {
                    name: $crate::gpu::gpu_constants!(@wgsl_name $name $($wgsl)?),
                    value: $crate::gpu::ConstantValue::from($name),
                    doc: concat!($($doc, "\n"),*),
                }
            ),*]
        }
    };
    (@wgsl_name $name:ident) => { stringify!($name) };
    (@wgsl_name $name:ident $wgsl:literal) => { $wgsl };
}
pub(crate) use gpu_constants;

#[cfg(test)]
mod tests {
    use super::*;

    gpu_struct! {
        /// A test struct:
        /// two lines.
        pub struct Sample as "SampleStruct" {
            /// A vector.
            pub position: [f32; 3] as "vec3<f32>",
            /// An id.
            pub id: u32,
            /// Four words.
            pub words: [u32; 4],
        }
    }

    #[test]
    fn a_declaration_gives_the_rust_layout_and_the_wgsl_text() {
        let declaration = StructDeclaration::of::<Sample>();
        assert_eq!(declaration.size, 32);
        let offsets: Vec<_> = declaration.fields.iter().map(|f| (f.name, f.offset, f.size)).collect();
        assert_eq!(offsets, [("position", 0, 12), ("id", 12, 4), ("words", 16, 16)]);
        assert_eq!(
            declaration.wgsl(),
            "// A test struct:\n// two lines.\nstruct SampleStruct {\n    // A vector.\n    position: vec3<f32>,\n    \
             // An id.\n    id: u32,\n    // Four words.\n    words: array<u32, 4>,\n}\n"
        );
    }

    gpu_struct! {
        /// A record of two rows.
        pub struct Packed {
            /// Three floats.
            pub position: [f32; 3] as "vec3<f32>",
            /// A word.
            pub id: u32,
            /// Two floats.
            pub uv: [f32; 2] as "vec2<f32>",
            /// A signed word.
            pub offset: i32,
            /// A float.
            pub scale: f32,
        }
    }

    /// A reader takes each field from its row and lanes, reinterpreting the words as the
    /// field's scalar, and parses with the struct and the array it requires.
    #[test]
    fn a_row_reader_reads_each_field_from_its_lanes() {
        let readers = RowReaders {
            row_function: "row_at",
            imports: vec!["gpu/test.wgsl"],
            structs: vec![StructDeclaration::of::<Packed>()],
        };
        let text = readers.wgsl();
        assert!(text.starts_with("// #import gpu/test.wgsl\n// #requires fn row_at(row: u32) -> vec4<u32>\n"));
        assert!(text.contains(
            "fn read_packed(first_row: u32, index: u32) -> Packed {\n    let row = first_row + index * 2u;\n"
        ));
        assert!(text.contains("let r1 = row_at(row + 1u);"), "{text}");
        assert!(
            text.contains(
                "return Packed(bitcast<vec3<f32>>(r0.xyz), r0.w, bitcast<vec2<f32>>(r1.xy), bitcast<i32>(r1.z), \
                 bitcast<f32>(r1.w));"
            ),
            "{text}"
        );
        let source = format!(
            "{}{} {{ return vec4<u32>(row); }}\n{text}",
            StructDeclaration::of::<Packed>().wgsl(),
            readers.declaration()
        );
        naga::front::wgsl::parse_str(&source).unwrap_or_else(|e| panic!("{}", e.emit_to_string(&source)));
        assert_eq!(snake_case("EmissiveTriangle"), "emissive_triangle");
    }

    /// A field that cannot come from one row's lanes is refused by name.
    #[test]
    #[should_panic(expected = "field `words` of SampleStruct (array<u32, 4>) cannot be read from 16-byte rows")]
    fn a_row_reader_refuses_an_array_field() {
        row_reader(&StructDeclaration::of::<Sample>(), "rows");
    }

    #[test]
    fn constants_are_written_as_wgsl_reads_them() {
        let constant = GpuConstant { name: "SMALL", value: ConstantValue::F32(1e-3), doc: " Small.\n" };
        assert_eq!(constant.wgsl(), "// Small.\nconst SMALL: f32 = 0.001f;\n");
        let module = naga::front::wgsl::parse_str(&constant.wgsl()).unwrap();
        assert_eq!(crate::constants::module_constants(&module), [("SMALL".to_string(), ConstantValue::F32(1e-3))]);
    }
}
