//! `--override` for `cargo xtask run`: what each flag names, checked against the
//! shader's declarations before anything is specialised.
//!
//! naga's pipeline-constant processing (what `Kernel::from_wgsl_with_overrides` runs)
//! keys an override declared with `@id(N)` by the number `N` as text and every other
//! override by its name, so `@id(3) override tile` could not be set as `tile=4`, only as
//! `3=4`. Here a flag may name an override either way, as docs/kernels.md documents: by
//! its name (`tile=4`), or by its `@id` number (`3=4`, or `@3=4`); [`resolve`] turns each
//! into naga's key. It refuses by name, before the shader is specialised, what naga would
//! refuse with a message naming neither the flag nor the limit: an override the shader
//! lacks, one given twice (by name and by number), a value its type cannot hold (a
//! fraction or a negative number for a `u32`, `true` or `false` for a number), one
//! without a default left unset, and a workgroup size outside naga's 1 to 16384 per
//! axis. A `bool` override takes `true` and `false` (or 1 and 0). Every message quotes
//! the flag as the user wrote it ([`OverrideFlag`]): `--override scale=1e39`, not the
//! number's forty digits.

use naga::{Expression, Handle, Module, Scalar, ScalarKind, TypeInner};

/// naga's validator refuses a workgroup size axis of 0 or above this
/// (`naga::valid::interface`, `MAX_WORKGROUP_SIZE`).
pub const NAGA_MAX_WORKGROUP_SIZE: u32 = 0x4000;

/// The overrides of a run, resolved against the shader.
#[derive(Clone, Debug, Default)]
pub struct ResolvedOverrides {
    /// What naga's pipeline-constant processing takes: per flag the `@id` number as text
    /// or the name, and the value.
    pub constants: Vec<(String, f64)>,
    /// The flags the entry point's workgroup size depends on, each as the user wrote
    /// it and what it names (`--override 3=64 (`tile`, @id(3))`), for errors about
    /// workgroup limits.
    pub workgroup_flags: Vec<String>,
}

/// One `--override KEY=VALUE` flag: what it names, its value as the user wrote it, and
/// that value as naga's pipeline constants take it.
#[derive(Clone, Debug, PartialEq)]
pub struct OverrideFlag {
    /// The override's name or `@id` number (`tile`, `3` or `@3`), trimmed.
    pub key: String,
    /// The value as written (`1e39`, `false`), trimmed: what messages quote.
    pub text: String,
    /// The value: the number, or 1 for `true` and 0 for `false`.
    pub value: f64,
}

impl OverrideFlag {
    /// Parses `KEY=VALUE` as `--override` takes it: VALUE a number, or `true` or
    /// `false` (for a `bool` override; [`resolve`] refuses them for numbers). The error
    /// is one line quoting `text`.
    pub fn parse(text: &str) -> Result<Self, String> {
        let (key, value) = text.split_once('=').ok_or_else(|| format!("`{text}`: expected NAME=VALUE"))?;
        let (key, written) = (key.trim(), value.trim());
        if key.is_empty() {
            return Err(format!("`{text}`: expected NAME=VALUE"));
        }
        let value = match written {
            "true" => 1.0,
            "false" => 0.0,
            _ => written.parse::<f64>().map_err(|_| {
                format!("`{text}`: value `{written}` is not a number (or `true`/`false` for a bool override)")
            })?,
        };
        Ok(OverrideFlag { key: key.to_string(), text: written.to_string(), value })
    }

    /// A flag setting `key` to the number `value`, written as Rust prints it.
    pub fn number(key: &str, value: f64) -> Self {
        OverrideFlag { key: key.to_string(), text: value.to_string(), value }
    }

    /// Whether the value was written `true` or `false`.
    fn is_boolean(&self) -> bool {
        self.text == "true" || self.text == "false"
    }
}

impl std::fmt::Display for OverrideFlag {
    /// `--override KEY=VALUE` as the user wrote it.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "--override {}={}", self.key, self.text)
    }
}

/// An override as people name it: `` `tile` (@id(3)) ``, `` `scale` `` or `@id(7)`.
fn describe(module: &Module, handle: Handle<naga::Override>) -> String {
    let o = &module.overrides[handle];
    match (&o.name, o.id) {
        (Some(name), Some(id)) => format!("`{name}` (@id({id}))"),
        (Some(name), None) => format!("`{name}`"),
        (None, Some(id)) => format!("@id({id})"),
        (None, None) => "an unnamed override".into(),
    }
}

/// Every override of `module`, for messages.
fn declared(module: &Module) -> String {
    let all: Vec<String> = module.overrides.iter().map(|(handle, _)| describe(module, handle)).collect();
    if all.is_empty() { "none".into() } else { all.join(", ") }
}

/// The override a flag's key names: its name, or its `@id` number (`3` or `@3`).
fn find(module: &Module, key: &str) -> Option<Handle<naga::Override>> {
    let number = key.strip_prefix('@').unwrap_or(key).parse::<u16>().ok();
    let by_name = module.overrides.iter().find(|(_, o)| o.name.as_deref() == Some(key));
    let by_id = number.and_then(|n| module.overrides.iter().find(|(_, o)| o.id == Some(n)));
    by_name.or(by_id).map(|(handle, _)| handle)
}

/// Whether `value` fits the scalar type `scalar`; `Err` says what the type takes.
fn fits(value: f64, scalar: Scalar) -> Result<(), String> {
    let whole = |low: f64, high: f64| {
        if value.is_finite() && value.fract() == 0.0 && value >= low && value <= high {
            Ok(())
        } else {
            Err(format!("whole numbers from {low} to {high}"))
        }
    };
    match (scalar.kind, scalar.width) {
        (ScalarKind::Bool, _) if value == 0.0 || value == 1.0 => Ok(()),
        (ScalarKind::Bool, _) => Err("`true` or `false` (or 1 or 0)".into()),
        (ScalarKind::Uint, 2) => whole(0.0, f64::from(u16::MAX)),
        (ScalarKind::Sint, 2) => whole(f64::from(i16::MIN), f64::from(i16::MAX)),
        (ScalarKind::Uint, 4) => whole(0.0, f64::from(u32::MAX)),
        (ScalarKind::Sint, 4) => whole(f64::from(i32::MIN), f64::from(i32::MAX)),
        (ScalarKind::Float, 2) if value.is_finite() && value.abs() <= 65504.0 => Ok(()),
        (ScalarKind::Float, 2) => Err("finite numbers of magnitude at most 65504".into()),
        (ScalarKind::Float, 4) if value.is_finite() && value.abs() <= f64::from(f32::MAX) => Ok(()),
        (ScalarKind::Float, 4) => Err(format!("finite numbers of magnitude at most {:e}", f32::MAX)),
        (ScalarKind::Float, _) if value.is_finite() => Ok(()),
        (ScalarKind::Float, _) => Err("finite numbers".into()),
        // 64-bit integers and other widths: naga converts, and says what it refuses.
        _ => Ok(()),
    }
}

/// The WGSL name of a scalar type.
fn type_name(scalar: Scalar) -> String {
    match scalar.kind {
        ScalarKind::Bool => "bool".into(),
        ScalarKind::Uint => format!("u{}", scalar.width * 8),
        ScalarKind::Sint => format!("i{}", scalar.width * 8),
        ScalarKind::Float => format!("f{}", scalar.width * 8),
        _ => format!("{scalar:?}"),
    }
}

/// Resolves `given` (`(key, value)` as the flags say) against `module`'s overrides
/// (module documentation); `entry` is the compute entry point whose workgroup size is
/// checked. Each error is one line naming the flag.
pub fn resolve(module: &Module, entry: &str, given: &[OverrideFlag]) -> Result<ResolvedOverrides, String> {
    let mut chosen: Vec<(Handle<naga::Override>, &OverrideFlag)> = Vec::new();
    for given in given {
        let key = given.key.as_str();
        let Some(handle) = find(module, key) else {
            let what = match key.strip_prefix('@').unwrap_or(key).parse::<u16>() {
                Ok(id) => format!("no override has @id({id})"),
                Err(_) => format!("`{key}` is not an override of this shader"),
            };
            return Err(format!("{given}: {what} (it declares: {})", declared(module)));
        };
        if let Some((_, first)) = chosen.iter().find(|(h, _)| *h == handle) {
            return Err(format!("{given}: {} is given twice ({first} first): give it once", describe(module, handle)));
        }
        if let TypeInner::Scalar(scalar) = module.types[module.overrides[handle].ty].inner {
            let takes = if given.is_boolean() && scalar.kind != ScalarKind::Bool {
                // `true` and `false` are for bools; the type's own range says what fits.
                let takes = fits(f64::NAN, scalar).err().unwrap_or_else(|| "numbers".into());
                Some(format!("{takes}, not `true` or `false`"))
            } else {
                fits(given.value, scalar).err()
            };
            if let Some(takes) = takes {
                return Err(format!(
                    "{given}: {} is a {}, which takes {takes}",
                    describe(module, handle),
                    type_name(scalar)
                ));
            }
        }
        chosen.push((handle, given));
    }
    if let Some((handle, _)) =
        module.overrides.iter().find(|(handle, o)| o.init.is_none() && !chosen.iter().any(|(h, _)| h == handle))
    {
        let o = &module.overrides[handle];
        let key = o.name.clone().or(o.id.map(|id| id.to_string())).unwrap_or_default();
        return Err(format!(
            "override {} has no default: give it a value (--override {key}=VALUE)",
            describe(module, handle)
        ));
    }
    let constants = chosen
        .iter()
        .map(|&(handle, given)| {
            let o = &module.overrides[handle];
            let key = match (o.id, &o.name) {
                (Some(id), _) => id.to_string(),
                (None, Some(name)) => name.clone(),
                (None, None) => String::new(),
            };
            (key, given.value)
        })
        .collect();
    let mut resolved = ResolvedOverrides { constants, workgroup_flags: Vec::new() };
    let Some(point) = module.entry_points.iter().find(|e| e.name == entry && e.stage == naga::ShaderStage::Compute)
    else {
        return Ok(resolved);
    };
    let Some(axes) = point.workgroup_size_overrides else {
        return Ok(resolved);
    };
    let values: Vec<(Handle<naga::Override>, f64)> = chosen.iter().map(|&(h, given)| (h, given.value)).collect();
    let mut used = Vec::new();
    let mut size: [Option<i128>; 3] = [None; 3];
    for (axis, expression) in axes.iter().enumerate() {
        size[axis] = match expression {
            Some(expression) => evaluate(module, *expression, &values, &mut used, 0),
            None => Some(i128::from(point.workgroup_size[axis])),
        };
    }
    resolved.workgroup_flags = chosen
        .iter()
        .filter(|(handle, _)| used.contains(handle))
        .map(|&(handle, given)| format!("{given}, which sets {}", describe(module, handle)))
        .collect();
    if let [Some(x), Some(y), Some(z)] = size
        && [x, y, z].iter().any(|&n| n < 1 || n > i128::from(NAGA_MAX_WORKGROUP_SIZE))
    {
        let from: Vec<String> = used.iter().map(|&h| describe(module, h)).collect();
        let flags = if resolved.workgroup_flags.is_empty() {
            "the overrides' defaults".to_string()
        } else {
            resolved.workgroup_flags.join("; ")
        };
        return Err(format!(
            "{flags}: the workgroup size of `{entry}` (from {}) would be {x}x{y}x{z}; naga takes 1 to \
             {NAGA_MAX_WORKGROUP_SIZE} per axis",
            from.join(", ")
        ));
    }
    Ok(resolved)
}

/// The integer value of the global expression `handle` with the overrides `values`
/// (the rest at their defaults), noting each override it reads in `used`; `None` for
/// what this small evaluator does not know (naga then decides).
fn evaluate(
    module: &Module,
    handle: Handle<Expression>,
    values: &[(Handle<naga::Override>, f64)],
    used: &mut Vec<Handle<naga::Override>>,
    depth: u32,
) -> Option<i128> {
    use naga::{BinaryOperator as B, Literal as L};
    if depth > 64 {
        return None;
    }
    if let Expression::Override(o) = module.global_expressions[handle] {
        if !used.contains(&o) {
            used.push(o);
        }
        return match values.iter().find(|(h, _)| *h == o) {
            // Whole numbers within the type's range (checked by `fits`).
            Some(&(_, value)) if value.fract() == 0.0 && value.abs() < 1e30 => Some(value as i128),
            Some(_) => None,
            None => module.overrides[o].init.and_then(|init| evaluate(module, init, values, used, depth + 1)),
        };
    }
    let mut at = |h| evaluate(module, h, values, used, depth + 1);
    match module.global_expressions[handle] {
        Expression::Literal(literal) => match literal {
            L::U32(v) => Some(i128::from(v)),
            L::I32(v) => Some(i128::from(v)),
            L::U16(v) => Some(i128::from(v)),
            L::I16(v) => Some(i128::from(v)),
            L::U64(v) => Some(i128::from(v)),
            L::I64(v) | L::AbstractInt(v) => Some(i128::from(v)),
            _ => None,
        },
        Expression::Constant(c) => at(module.constants[c].init),
        Expression::ZeroValue(_) => Some(0),
        Expression::As { expr, .. } => at(expr),
        Expression::Unary { op: naga::UnaryOperator::Negate, expr } => at(expr).and_then(i128::checked_neg),
        Expression::Binary { op, left, right } => {
            let (a, b) = (at(left)?, at(right)?);
            match op {
                B::Add => a.checked_add(b),
                B::Subtract => a.checked_sub(b),
                B::Multiply => a.checked_mul(b),
                B::Divide => a.checked_div(b),
                B::Modulo => a.checked_rem(b),
                B::ShiftLeft => u32::try_from(b).ok().filter(|&s| s < 64).and_then(|s| a.checked_shl(s)),
                B::ShiftRight => u32::try_from(b).ok().filter(|&s| s < 64).and_then(|s| a.checked_shr(s)),
                _ => None,
            }
        }
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn module(source: &str) -> Module {
        naga::front::wgsl::parse_str(source).unwrap()
    }

    const TILE: &str = "
        @id(3) override tile: u32 = 8;
        override scale: f32 = 1.0;
        override twice = tile * 2u;
        @compute @workgroup_size(twice, tile)
        fn main() { _ = scale; }";

    #[test]
    fn names_and_numbers_become_naga_s_keys() {
        let m = module(TILE);
        for key in ["tile", "3", "@3"] {
            let resolved = resolve(&m, "main", &[OverrideFlag::number(key, 4.0)]).unwrap();
            assert_eq!(resolved.constants, vec![("3".to_string(), 4.0)], "{key}");
            assert_eq!(resolved.workgroup_flags, vec![format!("--override {key}=4, which sets `tile` (@id(3))")]);
        }
        let resolved = resolve(&m, "main", &[OverrideFlag::number("scale", 0.5)]).unwrap();
        assert_eq!(resolved.constants, vec![("scale".to_string(), 0.5)]);
        assert!(resolved.workgroup_flags.is_empty());
    }

    #[test]
    fn what_naga_would_refuse_is_named() {
        let m = module(TILE);
        let error = |given: &[(&str, f64)]| {
            let given: Vec<OverrideFlag> = given.iter().map(|(k, v)| OverrideFlag::number(k, *v)).collect();
            resolve(&m, "main", &given).unwrap_err()
        };
        let e = error(&[("3", 100000.0)]);
        assert!(e.contains("--override 3=100000") && e.contains("200000x100000x1") && e.contains("16384"), "{e}");
        let e = error(&[("tile", 0.0)]);
        assert!(e.contains("0x0x1"), "{e}");
        let e = error(&[("tile", 2.5)]);
        assert!(e.contains("--override tile=2.5") && e.contains("u32"), "{e}");
        let e = error(&[("scale", f64::INFINITY)]);
        assert!(e.contains("f32"), "{e}");
        let e = error(&[("9", 1.0)]);
        assert!(e.contains("no override has @id(9)") && e.contains("`tile` (@id(3))"), "{e}");
        let e = error(&[("tile", 4.0), ("@3", 2.0)]);
        assert!(e.contains("--override @3=2") && e.contains("twice") && e.contains("--override tile=4"), "{e}");
        let m = module("override n: u32; @compute @workgroup_size(1) fn main() { _ = n; }");
        let e = resolve(&m, "main", &[]).unwrap_err();
        assert!(e.contains("`n` has no default") && e.contains("--override n=VALUE"), "{e}");
    }

    const FLAGS: &str = "
        @id(0) override scale: f32 = 1.5;
        @id(7) override enabled: bool = true;
        override depth: i32 = -2;
        @compute @workgroup_size(1)
        fn main() { _ = scale; _ = enabled; _ = depth; }";

    /// `true` and `false` set a bool override by name or number, and are refused, by
    /// name, for a number; every message quotes the value as written.
    #[test]
    fn bools_take_true_and_false_and_messages_quote_the_flag() {
        let m = module(FLAGS);
        let parse = |text: &str| OverrideFlag::parse(text).unwrap();
        for (text, value) in [("7=false", 0.0), ("enabled=true", 1.0), ("@7=0", 0.0), ("enabled = false", 0.0)] {
            let resolved = resolve(&m, "main", &[parse(text)]).unwrap();
            assert_eq!(resolved.constants, vec![("7".to_string(), value)], "{text}");
        }
        let e = resolve(&m, "main", &[parse("depth=true")]).unwrap_err();
        assert!(e.starts_with("--override depth=true: `depth` is a i32") && e.contains("not `true` or `false`"), "{e}");
        let e = resolve(&m, "main", &[parse("0=false")]).unwrap_err();
        assert!(e.contains("--override 0=false") && e.contains("`scale` (@id(0)) is a f32"), "{e}");
        let e = resolve(&m, "main", &[parse("enabled=2")]).unwrap_err();
        assert!(e.contains("--override enabled=2") && e.contains("`true` or `false`"), "{e}");
        let e = resolve(&m, "main", &[parse("scale=1e39")]).unwrap_err();
        assert!(e.starts_with("--override scale=1e39: `scale` (@id(0)) is a f32"), "{e}");
        let e = resolve(&m, "main", &[parse("scale=1e39"), parse("0=2")]).unwrap_err();
        assert!(e.contains("1e39") && !e.contains("0000000000"), "{e}");
        let e = OverrideFlag::parse("enabled=yes").unwrap_err();
        assert!(e.contains("`enabled=yes`") && e.contains("`yes`") && e.contains("true"), "{e}");
        assert!(OverrideFlag::parse("=1").is_err() && OverrideFlag::parse("scale").is_err());
    }
}
