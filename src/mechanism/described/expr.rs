//! The arithmetic of a walker's description (docs/model.md section 13): a numeric field is a number or an
//! expression over the walker's parameters, parsed once into a small tree ([`Expr`]) and evaluated over any
//! [`Real`], so that a parameter carrying a dual number carries `d/dp` through the very kinematics the walk uses.
//!
//! The grammar: numbers, parameter names, the constant `pi`, `sin(...)` and `cos(...)`, unary minus,
//! `+ - * /` with the usual precedence, and parentheses.
//!
//! Hand-written (a recursive-descent parser of a page) rather than a crate: evalexpr, meval and fasteval
//! evaluate `f64` only, and exmex, which is generic, parses an expression for one scalar type and its operator
//! factory (a `FlatEx<T, Ops>` per type, with `T: FromStr`), so the same description would be parsed again for
//! every dual number type and the duals would need a text form; here one tree evaluates over every [`Real`].

use super::super::Real;

/// A parsed expression.
#[derive(Debug, Clone, PartialEq)]
pub enum Expr {
    /// A number.
    Number(f64),
    /// The parameter of this index (in the description's `[parameters]`).
    Parameter(usize),
    /// `-a`.
    Neg(Box<Expr>),
    /// `a op b`.
    Binary(Op, Box<Expr>, Box<Expr>),
    /// `sin(a)` or `cos(a)`.
    Call(Function, Box<Expr>),
}

/// A binary operator.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Op {
    /// `+`.
    Add,
    /// `-`.
    Sub,
    /// `*`.
    Mul,
    /// `/`.
    Div,
}

/// A function of one argument.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Function {
    /// `sin`.
    Sin,
    /// `cos`.
    Cos,
}

/// Why an expression could not be parsed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ExprError {
    /// A name that is no parameter (nor `pi`, `sin`, `cos`).
    #[error("unknown parameter `{name}` in `{text}` (the parameters: {known})")]
    UnknownParameter {
        /// The name.
        name: String,
        /// The expression.
        text: String,
        /// The parameters there are.
        known: String,
    },
    /// Anything else: a stray character, a missing operand or parenthesis.
    #[error("cannot read `{text}` as an expression: {reason} (numbers, parameters, pi, sin(), cos(), + - * / and parentheses)")]
    Syntax {
        /// The expression.
        text: String,
        /// What is wrong, and where.
        reason: String,
    },
}

impl Expr {
    /// Parse `text`, resolving names among `parameters`.
    pub fn parse(text: &str, parameters: &[&str]) -> Result<Expr, ExprError> {
        let mut parser = Parser {
            text,
            tokens: tokens(text)?,
            at: 0,
            parameters,
        };
        let e = parser.sum()?;
        match parser.tokens.get(parser.at) {
            None => Ok(e),
            Some(t) => Err(parser.syntax(format!("unexpected `{}`", t.shown()))),
        }
    }

    /// The value with the parameters `values` (by index).
    pub fn eval<T: Real>(&self, values: &[T]) -> T {
        match self {
            Expr::Number(x) => T::lit(*x),
            Expr::Parameter(i) => values[*i],
            Expr::Neg(a) => -a.eval(values),
            Expr::Binary(op, a, b) => {
                let (a, b) = (a.eval(values), b.eval(values));
                match op {
                    Op::Add => a + b,
                    Op::Sub => a - b,
                    Op::Mul => a * b,
                    Op::Div => a / b,
                }
            }
            Expr::Call(f, a) => match f {
                Function::Sin => a.eval(values).sin(),
                Function::Cos => a.eval(values).cos(),
            },
        }
    }

    /// Whether the expression uses a parameter.
    pub fn uses_parameters(&self) -> bool {
        match self {
            Expr::Number(_) => false,
            Expr::Parameter(_) => true,
            Expr::Neg(a) | Expr::Call(_, a) => a.uses_parameters(),
            Expr::Binary(_, a, b) => a.uses_parameters() || b.uses_parameters(),
        }
    }
}

/// A token of an expression.
#[derive(Debug, Clone, PartialEq)]
enum Token {
    Number(f64),
    Name(String),
    Symbol(char),
}

impl Token {
    fn shown(&self) -> String {
        match self {
            Token::Number(x) => x.to_string(),
            Token::Name(n) => n.clone(),
            Token::Symbol(c) => c.to_string(),
        }
    }
}

/// The tokens of `text`.
fn tokens(text: &str) -> Result<Vec<Token>, ExprError> {
    let bytes = text.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < bytes.len() {
        let c = bytes[i] as char;
        if c.is_ascii_whitespace() {
            i += 1;
        } else if c.is_ascii_digit() || c == '.' {
            let start = i;
            while i < bytes.len() && (bytes[i].is_ascii_alphanumeric() || bytes[i] == b'.') {
                // An exponent's sign belongs to the number: 1e-3.
                let exponent = matches!(bytes[i], b'e' | b'E');
                i += 1;
                if exponent && i < bytes.len() && matches!(bytes[i], b'+' | b'-') {
                    i += 1;
                }
            }
            let literal = &text[start..i];
            let x: f64 = literal.parse().map_err(|_| ExprError::Syntax {
                text: text.to_string(),
                reason: format!("`{literal}` is not a number"),
            })?;
            out.push(Token::Number(x));
        } else if c.is_ascii_alphabetic() || c == '_' {
            let start = i;
            while i < bytes.len() && (bytes[i].is_ascii_alphanumeric() || bytes[i] == b'_') {
                i += 1;
            }
            out.push(Token::Name(text[start..i].to_string()));
        } else if "+-*/()".contains(c) {
            out.push(Token::Symbol(c));
            i += 1;
        } else {
            let c = text[i..].chars().next().unwrap_or('?');
            return Err(ExprError::Syntax {
                text: text.to_string(),
                reason: format!("unexpected character `{c}`"),
            });
        }
    }
    Ok(out)
}

/// A recursive-descent parser: `sum = product (('+' | '-') product)*`, `product = unary (('*' | '/') unary)*`,
/// `unary = '-' unary | atom`, `atom = number | name | name '(' sum ')' | '(' sum ')'`.
struct Parser<'a> {
    text: &'a str,
    tokens: Vec<Token>,
    at: usize,
    parameters: &'a [&'a str],
}

impl Parser<'_> {
    fn syntax(&self, reason: String) -> ExprError {
        ExprError::Syntax {
            text: self.text.to_string(),
            reason,
        }
    }

    fn next(&mut self) -> Option<Token> {
        let t = self.tokens.get(self.at).cloned();
        self.at += usize::from(t.is_some());
        t
    }

    fn peek_symbol(&self, symbols: &str) -> Option<char> {
        match self.tokens.get(self.at) {
            Some(Token::Symbol(c)) if symbols.contains(*c) => Some(*c),
            _ => None,
        }
    }

    fn sum(&mut self) -> Result<Expr, ExprError> {
        let mut e = self.product()?;
        while let Some(c) = self.peek_symbol("+-") {
            self.at += 1;
            let op = if c == '+' { Op::Add } else { Op::Sub };
            e = Expr::Binary(op, Box::new(e), Box::new(self.product()?));
        }
        Ok(e)
    }

    fn product(&mut self) -> Result<Expr, ExprError> {
        let mut e = self.unary()?;
        while let Some(c) = self.peek_symbol("*/") {
            self.at += 1;
            let op = if c == '*' { Op::Mul } else { Op::Div };
            e = Expr::Binary(op, Box::new(e), Box::new(self.unary()?));
        }
        Ok(e)
    }

    fn unary(&mut self) -> Result<Expr, ExprError> {
        if self.peek_symbol("-").is_some() {
            self.at += 1;
            return Ok(Expr::Neg(Box::new(self.unary()?)));
        }
        self.atom()
    }

    fn atom(&mut self) -> Result<Expr, ExprError> {
        match self.next() {
            Some(Token::Number(x)) => Ok(Expr::Number(x)),
            Some(Token::Symbol('(')) => {
                let e = self.sum()?;
                self.close()?;
                Ok(e)
            }
            Some(Token::Name(name)) => self.named(name),
            Some(t) => Err(self.syntax(format!("unexpected `{}`", t.shown()))),
            None => Err(self.syntax("it ends where an operand is expected".to_string())),
        }
    }

    fn close(&mut self) -> Result<(), ExprError> {
        match self.next() {
            Some(Token::Symbol(')')) => Ok(()),
            _ => Err(self.syntax("a `(` is not closed".to_string())),
        }
    }

    /// A parameter, `pi`, or a call of `sin` or `cos`.
    fn named(&mut self, name: String) -> Result<Expr, ExprError> {
        let function = match name.as_str() {
            "sin" => Some(Function::Sin),
            "cos" => Some(Function::Cos),
            _ => None,
        };
        if let Some(f) = function {
            if self.next() != Some(Token::Symbol('(')) {
                return Err(self.syntax(format!("`{name}` takes its argument in parentheses")));
            }
            let a = self.sum()?;
            self.close()?;
            return Ok(Expr::Call(f, Box::new(a)));
        }
        if let Some(i) = self.parameters.iter().position(|p| *p == name) {
            return Ok(Expr::Parameter(i));
        }
        if name == "pi" {
            return Ok(Expr::Number(std::f64::consts::PI));
        }
        Err(ExprError::UnknownParameter {
            name,
            text: self.text.to_string(),
            known: self.parameters.join(", "),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn value(text: &str) -> f64 {
        Expr::parse(text, &["a", "b_2"]).unwrap().eval(&[2.0, 0.5])
    }

    /// Precedence, associativity, unary minus, functions, exponents and parameters.
    #[test]
    fn expressions_evaluate_by_the_usual_rules() {
        assert_eq!(value("1 + 2 * 3"), 7.0);
        assert_eq!(value("(1 + 2) * 3"), 9.0);
        assert_eq!(value("8 / 4 / 2"), 1.0);
        assert_eq!(value("5 - 3 - 1"), 1.0);
        assert_eq!(value("-a * -b_2"), 1.0);
        assert_eq!(value("a - -b_2"), 2.5);
        assert_eq!(value("1e-3 * 2E+3"), 2.0);
        assert_eq!(value("sin(pi / 2) + cos(0)"), 2.0);
        assert_eq!(value("a * (b_2 + 1) / 3"), 1.0);
    }

    /// Every malformed expression is refused with what is wrong.
    #[test]
    fn bad_expressions_say_what_is_wrong() {
        let err = |text: &str| Expr::parse(text, &["a"]).unwrap_err().to_string();
        assert!(err("a + c").contains("unknown parameter `c`"));
        assert!(err("a +").contains("ends where an operand"));
        assert!(err("(a + 1").contains("not closed"));
        assert!(err("a $ 1").contains("unexpected character `$`"));
        assert!(err("a 1").contains("unexpected `1`"));
        assert!(err("sin a").contains("in parentheses"));
        assert!(err("1.2.3").contains("not a number"));
        assert!(err("").contains("ends where an operand"));
    }
}
