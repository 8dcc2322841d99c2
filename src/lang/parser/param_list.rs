//! Parameter lists after a directive (parser.cpp's `parseParams`): items
//! `"type name" value…` while the next token is a quoted string, their
//! declarations checked and their values read (bare or bracketed, numbers
//! or strings), so that the token stream stays in step after an error.

use super::*;

impl<'l> Parser<'l> {
    /// A parameter list: items while the next token is a quoted string.
    pub(super) fn param_list(&mut self) -> PResult<ParamList> {
        let mut list = ParamList::default();
        let mut failed = false;
        while let Some(t) = self.peek() {
            let TokKind::Str { escaped } = t.kind else {
                break;
            };
            self.next();
            match self.param(t, escaped) {
                Ok(Some(p)) => list.push(p),
                Ok(None) => {}
                Err(()) => failed = true,
            }
            if self.diags.errors.len() >= MAX_ERRORS {
                return Err(());
            }
        }
        if failed {
            Err(())
        } else {
            Ok(list)
        }
    }

    fn param(&mut self, decl: Token, escaped: bool) -> PResult<Option<Param>> {
        let decl_text = dequote(self.text(decl), escaped);
        let parsed =
            split_declaration(&decl_text).map(|(_, (t, n))| (t.to_string(), n.to_string()));
        // Values are read in any case, so that the stream stays in step.
        let quoted = parsed
            .as_ref()
            .ok()
            .and_then(|(t, _)| ParamType::from_name(t))
            .is_some_and(ParamType::wants_strings);
        let (mut nums, strs, values_loc) = self.values(decl, quoted)?;
        let (ty_name, name) = match parsed {
            Ok(x) => x,
            Err(_) => {
                self.error(
                    decl.loc,
                    format!("bad parameter declaration \"{decl_text}\": expected \"type name\""),
                    "expected two words: a type and a name",
                    None,
                );
                return Err(());
            }
        };
        let Some(&(type_name, ty)) = TYPE_NAMES.iter().find(|(n, _)| *n == ty_name) else {
            let names: Vec<&str> = TYPE_NAMES.iter().map(|(n, _)| *n).collect();
            let help = closest(&ty_name, &names).map(|s| format!("did you mean \"{s} {name}\"?"));
            self.error(
                decl.loc,
                format!("unknown parameter type `{ty_name}` in \"{decl_text}\""),
                "not a pbrt-v3 parameter type",
                help.or_else(|| Some(format!("the types are: {}", names.join(" ")))),
            );
            return Err(());
        };
        if !nums.is_empty() && !strs.is_empty() {
            self.error(
                values_loc,
                format!("parameter \"{name}\" mixes strings and numbers"),
                "strings and numbers",
                None,
            );
            return Err(());
        }
        let values = if ty.wants_strings() || (ty == ParamType::Spectrum && !strs.is_empty()) {
            if !nums.is_empty() {
                self.error(values_loc, format!("parameter \"{name}\" has type {type_name}: its values must be quoted strings, found numbers"), "expected quoted strings", None);
                return Err(());
            }
            if ty == ParamType::Bool {
                let mut bools = Vec::with_capacity(strs.len());
                for s in strs {
                    match s.as_str() {
                        "true" => bools.push(true),
                        "false" => bools.push(false),
                        _ => {
                            self.warn(values_loc, format!("bool parameter \"{name}\" has value \"{s}\", neither \"true\" nor \"false\": taken as false (as pbrt-v3)"), "expected \"true\" or \"false\"");
                            bools.push(false);
                        }
                    }
                }
                Values::Bools(bools)
            } else {
                Values::Strs(strs)
            }
        } else {
            if !strs.is_empty() {
                self.error(values_loc, format!("parameter \"{name}\" has type {type_name}: its values must be numbers, found strings"), "expected numbers", None);
                return Err(());
            }
            if ty == ParamType::Integer {
                if let Some(bad) = nums
                    .iter()
                    .find(|v| v.fract() != 0.0 || v.abs() > i32::MAX as f64)
                {
                    self.error(values_loc, format!("integer parameter \"{name}\" has value {bad}, which is not a 32-bit integer"), "expected integers", None);
                    return Err(());
                }
            }
            let arity = if ty == ParamType::Spectrum {
                2
            } else {
                ty.arity()
            };
            if ty == ParamType::Spectrum && nums.len() % 2 != 0 {
                // pbrt-v3 warns and drops the extra value.
                self.warn(values_loc, format!("parameter \"{type_name} {name}\" has {} numbers, an odd count: the last is ignored (as pbrt-v3)", nums.len()), "odd count");
                nums.pop();
            }
            if nums.len() % arity != 0 {
                self.error(values_loc, format!("parameter \"{type_name} {name}\" has {} numbers, not a multiple of {arity}", nums.len()), format!("{} values", nums.len()), None);
                return Err(());
            }
            Values::Nums(nums)
        };
        Ok(Some(Param {
            ty,
            type_name,
            name,
            values,
            loc: decl.loc,
            values_loc,
            used: Cell::new(false),
        }))
    }

    /// Reads `[ v… ]` or one value. Returns numbers, strings and their span.
    fn values(&mut self, decl: Token, quoted: bool) -> PResult<(Vec<f64>, Vec<String>, Loc)> {
        let Some(t) = self.next() else {
            self.error(
                decl.loc,
                "parameter has no value: the file ends",
                "this parameter",
                None,
            );
            return Err(());
        };
        match t.kind {
            TokKind::Str { escaped } => {
                Ok((Vec::new(), vec![dequote(self.text(t), escaped)], t.loc))
            }
            TokKind::Bare => {
                if directive_kind(self.text(t)).is_some() {
                    self.peeked = Some(t);
                    self.error(
                        decl.loc,
                        "parameter has no value",
                        "a value or `[` must follow",
                        None,
                    );
                    return Err(());
                }
                if quoted && parse_number(self.text(t).as_bytes()).is_err() {
                    let w = self.text(t).to_string();
                    self.error(
                        t.loc,
                        format!("value `{w}` must be in double quotes (\"{w}\")"),
                        "expected a quoted string",
                        None,
                    );
                    return Err(());
                }
                Ok((vec![self.number(t)?], Vec::new(), t.loc))
            }
            TokKind::RBracket => {
                self.error(
                    t.loc,
                    "unbalanced brackets: `]` without `[`",
                    "unexpected `]`",
                    None,
                );
                Err(())
            }
            TokKind::LBracket => {
                let mut nums = Vec::new();
                let mut strs = Vec::new();
                let mut ok = true;
                loop {
                    if ok && strs.is_empty() {
                        self.number_run(&mut nums);
                    }
                    let Some(v) = self.next() else {
                        self.error(
                            t.loc,
                            "unbalanced brackets: `[` is never closed",
                            "this `[`",
                            None,
                        );
                        return Err(());
                    };
                    match v.kind {
                        TokKind::RBracket => {
                            return if ok {
                                Ok((nums, strs, t.loc.to(v.loc)))
                            } else {
                                Err(())
                            }
                        }
                        TokKind::Bare => match self.number_text(v) {
                            Ok(x) => nums.push(x),
                            Err(e) => {
                                if directive_kind(self.text(v)).is_some() {
                                    self.peeked = Some(v);
                                    self.error(
                                        t.loc,
                                        "unbalanced brackets: `[` is never closed",
                                        "this `[`",
                                        None,
                                    );
                                    return Err(());
                                }
                                if ok && quoted {
                                    let w = self.text(v).to_string();
                                    self.error(
                                        v.loc,
                                        format!("value `{w}` must be in double quotes (\"{w}\")"),
                                        "expected a quoted string",
                                        None,
                                    );
                                } else if ok {
                                    self.bad_number(v, e);
                                }
                                ok = false;
                            }
                        },
                        TokKind::Str { escaped } => strs.push(dequote(self.text(v), escaped)),
                        TokKind::LBracket => {
                            self.error(
                                v.loc,
                                "unbalanced brackets: `[` inside `[ ]`",
                                "nested `[`",
                                None,
                            );
                            return Err(());
                        }
                    }
                }
            }
        }
    }
}
