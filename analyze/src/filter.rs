//! `COLUMN OP VALUE` conditions of `analyze summary --filter` (parsed here, without polars,
//! so the command line parses them in every build; [`crate::summary`] applies them).

/// A comparison in a filter.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Op {
    Eq,
    Ne,
    Lt,
    Le,
    Gt,
    Ge,
}

/// `column <op> value`, parsed from `"z_rms_m<0.05"`, `"run=two-elbow"`, `"status != complete"`.
#[derive(Debug, Clone, PartialEq)]
pub struct Filter {
    pub column: String,
    pub op: Op,
    pub value: String,
}

impl std::str::FromStr for Filter {
    type Err = String;
    fn from_str(s: &str) -> Result<Filter, String> {
        // two-character operators first
        const OPS: [(&str, Op); 7] = [
            ("!=", Op::Ne),
            ("<=", Op::Le),
            (">=", Op::Ge),
            ("==", Op::Eq),
            ("=", Op::Eq),
            ("<", Op::Lt),
            (">", Op::Gt),
        ];
        let (at, sym, op) = OPS
            .iter()
            .filter_map(|&(sym, op)| s.find(sym).map(|at| (at, sym, op)))
            .min_by_key(|&(at, sym, _)| (at, std::cmp::Reverse(sym.len())))
            .ok_or_else(|| format!("{s:?}: expected COLUMN OP VALUE with OP one of = != < <= > >="))?;
        let column = s[..at].trim().to_string();
        let value = s[at + sym.len()..].trim().to_string();
        if column.is_empty() || value.is_empty() {
            return Err(format!("{s:?}: expected COLUMN OP VALUE, e.g. z_rms_m<0.05 or run=two-elbow"));
        }
        Ok(Filter { column, op, value })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn filters_parse_with_the_longest_operator_at_the_first_position() {
        let f: Filter = "z_rms_m <= 0.05".parse().unwrap();
        assert_eq!((f.column.as_str(), f.op, f.value.as_str()), ("z_rms_m", Op::Le, "0.05"));
        let f: Filter = "run=two-elbow".parse().unwrap();
        assert_eq!((f.column.as_str(), f.op, f.value.as_str()), ("run", Op::Eq, "two-elbow"));
        let f: Filter = "status!=failed".parse().unwrap();
        assert_eq!(f.op, Op::Ne);
        let f: Filter = "E_j>1e3".parse().unwrap();
        assert_eq!((f.op, f.value.as_str()), (Op::Gt, "1e3"));
        // a value may contain operator characters after the first operator
        let f: Filter = "error=a<b".parse().unwrap();
        assert_eq!((f.column.as_str(), f.op, f.value.as_str()), ("error", Op::Eq, "a<b"));
        for bad in ["E_j", "=3", "E_j<", ""] {
            assert!(bad.parse::<Filter>().is_err(), "{bad:?}");
        }
    }
}
