//! Matrix arithmetic on matrices laid out as in memory: `columns` columns of `rows`
//! f32 values, each column padded to 4 words when `rows` is 3. Products sum in order
//! without fused multiply-add, starting from the first product rather than +0 (so that
//! products that are all -0 sum to -0, as on GPUs).

use naga::{BinaryOperator, TypeInner, VectorSize};

fn f(x: u32) -> f32 {
    f32::from_bits(x)
}

/// Words per column.
pub(super) fn column_words(rows: VectorSize) -> usize {
    if rows == VectorSize::Tri { 4 } else { rows as usize }
}

fn matrix_vector(m: &[u32], columns: usize, rows: VectorSize, v: &[u32]) -> Vec<u32> {
    let stride = column_words(rows);
    (0..rows as usize)
        .map(|i| (1..columns).fold(f(m[i]) * f(v[0]), |acc, k| acc + f(m[k * stride + i]) * f(v[k])).to_bits())
        .collect()
}

fn vector_matrix(v: &[u32], m: &[u32], columns: usize, rows: VectorSize) -> Vec<u32> {
    let stride = column_words(rows);
    (0..columns)
        .map(|j| {
            let column = j * stride;
            (1..rows as usize).fold(f(v[0]) * f(m[column]), |acc, i| acc + f(v[i]) * f(m[column + i])).to_bits()
        })
        .collect()
}

/// `a op b` where at least one operand is a matrix; `None` if not a matrix operation.
pub(super) fn binary(op: BinaryOperator, ta: &TypeInner, a: &[u32], tb: &TypeInner, b: &[u32]) -> Option<Vec<u32>> {
    use BinaryOperator as B;
    match (op, ta, tb) {
        (B::Multiply, TypeInner::Matrix { columns, rows, .. }, TypeInner::Vector { .. }) => {
            Some(matrix_vector(a, *columns as usize, *rows, b))
        }
        (B::Multiply, TypeInner::Vector { .. }, TypeInner::Matrix { columns, rows, .. }) => {
            Some(vector_matrix(a, b, *columns as usize, *rows))
        }
        (
            B::Multiply,
            TypeInner::Matrix { columns: inner, rows, .. },
            TypeInner::Matrix { columns, rows: right_rows, .. },
        ) => {
            let (left_stride, right_stride) = (column_words(*rows), column_words(*right_rows));
            let mut out = vec![0u32; *columns as usize * left_stride];
            for j in 0..*columns as usize {
                let column = &b[j * right_stride..j * right_stride + *right_rows as usize];
                let product = matrix_vector(a, *inner as usize, *rows, column);
                out[j * left_stride..j * left_stride + product.len()].copy_from_slice(&product);
            }
            Some(out)
        }
        (B::Multiply, TypeInner::Matrix { .. }, TypeInner::Scalar(_)) => {
            Some(a.iter().map(|&x| (f(x) * f(b[0])).to_bits()).collect())
        }
        (B::Multiply, TypeInner::Scalar(_), TypeInner::Matrix { .. }) => {
            Some(b.iter().map(|&x| (f(a[0]) * f(x)).to_bits()).collect())
        }
        (B::Add | B::Subtract, TypeInner::Matrix { .. }, TypeInner::Matrix { .. }) => Some(
            a.iter().zip(b).map(|(&x, &y)| if op == B::Add { f(x) + f(y) } else { f(x) - f(y) }.to_bits()).collect(),
        ),
        _ => None,
    }
}

/// `transpose(m)` of a `columns × rows` matrix.
pub(super) fn transpose(m: &[u32], columns: VectorSize, rows: VectorSize) -> Vec<u32> {
    let (stride, out_stride) = (column_words(rows), column_words(columns));
    let mut out = vec![0u32; rows as usize * out_stride];
    for j in 0..columns as usize {
        for i in 0..rows as usize {
            out[i * out_stride + j] = m[j * stride + i];
        }
    }
    out
}

/// `determinant(m)` of a square matrix, by cofactor expansion.
pub(super) fn determinant(m: &[u32], size: VectorSize) -> u32 {
    let stride = column_words(size);
    let n = size as usize;
    let at = |column: usize, row: usize| f(m[column * stride + row]);
    fn det(values: &[f32], n: usize) -> f32 {
        if n == 1 {
            return values[0];
        }
        if n == 2 {
            return values[0] * values[3] - values[2] * values[1];
        }
        let term = |column: usize| {
            let minor: Vec<f32> = (0..n)
                .filter(|&c| c != column)
                .flat_map(|c| (1..n).map(move |r| (c, r)))
                .map(|(c, r)| values[c * n + r])
                .collect();
            let sign = if column.is_multiple_of(2) { 1.0 } else { -1.0 };
            sign * values[column * n] * det(&minor, n - 1)
        };
        (1..n).fold(term(0), |total, column| total + term(column))
    }
    let values: Vec<f32> = (0..n).flat_map(|c| (0..n).map(move |r| (c, r))).map(|(c, r)| at(c, r)).collect();
    det(&values, n).to_bits()
}
