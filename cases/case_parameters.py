"""The parameters of the case inputs, read from the inputs themselves (one source).

- The names a case accepts are its `variable NAME index DEFAULT` lines (the case file and the
  includes it reads); any other name given with -v / -var is refused with the close names.
- The values a case refuses are the one-line rules `if "CONDITION" then "error MESSAGE"` of
  `include/validate.in` and of the case file; the runner applies the same lines before its
  (expensive) preparation, LIGGGHTS applies them when the input runs.
"""
from __future__ import annotations

import ast
import difflib
import operator
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Iterable, Mapping

CASE_DIR = Path(__file__).resolve().parent
CASES = ("periodic", "nonperiodic", "full")
# Variables of the case inputs that the runner sets from its own options.
RUNNER_SET = {
    "case_dir": "the runner's cases/ directory",
    "out_dir": "--out",
    "mesh_dir": "the scale's meshes (--scale, --mesh-tolerance)",
    "zones_file": "the meshes' zones.txt",
    "fill_file": "the runner's static fill",
    "feed_file": "the runner's feed regions (--feed-at)",
    "domain_length": "the meshes' zones.txt",
    "start": "the runner (a run starts from its fill; job segments: cases/slurm)",
    "restart_file": "the runner (a run starts from its fill; job segments: cases/slurm)",
}

_INDEX = re.compile(r"^\s*variable\s+(\w+)\s+index\s+(\S+)", re.MULTILINE)
_INCLUDE = re.compile(r"^\s*include\s+\$\{case_dir\}/include/(\S+)", re.MULTILINE)
_RULE = re.compile(r'^\s*if\s+"([^"]+)"\s+then\s+"error\s+([^"]+)"\s*$', re.MULTILINE)
_NUMBER = re.compile(r"^[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$")


class ParameterError(ValueError):
    """A case parameter that no run can mean: the message is the one line the user sees."""


@dataclass(frozen=True)
class Rule:
    condition: str    # LIGGGHTS boolean, true when the value is refused
    message: str      # the error text (with ${name} placeholders)
    source: str       # file name, for the docs

    def names(self) -> set[str]:
        return {a or b for a, b in re.findall(r"\$\{(\w+)\}|v_(\w+)", self.condition)}


def case_input(case: str) -> Path:
    if case not in CASES:
        raise ParameterError(f"case '{case}' is not allowed: use one of {', '.join(CASES)}")
    return CASE_DIR / f"in.tsg_{case}"


def input_files(case: str) -> list[Path]:
    """The case file and every include it (and they) read from cases/include/; an include named
    through a variable (screws_${screw_drive}.in) stands for every file that matches."""
    seen: list[Path] = []
    pending = [case_input(case)]
    while pending:
        path = pending.pop(0)
        if path in seen:
            continue
        seen.append(path)
        for name in _INCLUDE.findall(path.read_text()):
            pattern = re.sub(r"\$\{\w+\}", "*", name)
            pending += sorted((CASE_DIR / "include").glob(pattern))
    return seen


def index_lines(path: Path) -> list[str]:
    """The `variable NAME index DEFAULT` declarations of one input file, as written (comments dropped):
    for an input that declares the case's defaults itself (benchmarks/paper_cost.py)."""
    return [match.group(0).strip() for match in _INDEX.finditer(path.read_text())]


def defined_variables(case: str) -> dict[str, str]:
    """name -> default text of every `variable ... index` line the case reads."""
    defaults: dict[str, str] = {}
    for path in input_files(case):
        for name, value in _INDEX.findall(path.read_text()):
            defaults.setdefault(name, value)
    return defaults


def check_names(names: Iterable[str], case: str, option: str = "-v") -> None:
    known = defined_variables(case)
    for name in names:
        if name in RUNNER_SET:
            raise ParameterError(f"{option} {name}: set by the runner from {RUNNER_SET[name]}, not settable here")
        if name not in known:
            close = difflib.get_close_matches(name, [k for k in known if k not in RUNNER_SET], n=4, cutoff=0.6)
            hint = f"did you mean {', '.join(close)}?" if close else "see the `variable ... index` lines of the case"
            raise ParameterError(f"{option} {name}: the {case} case has no variable '{name}' ({hint})")


def rules(case: str) -> list[Rule]:
    """The value rules that apply to a case: its own lines and those of the includes it reads."""
    found = []
    for path in input_files(case):
        found += [Rule(c, m, path.name) for c, m in _RULE.findall(path.read_text())]
    return found


_OPERATORS: dict[type, Callable[..., Any]] = {
              ast.Add: operator.add, ast.Sub: operator.sub, ast.Mult: operator.mul, ast.Div: operator.truediv,
              ast.USub: operator.neg, ast.UAdd: operator.pos, ast.Not: operator.not_,
              ast.Lt: operator.lt, ast.LtE: operator.le, ast.Gt: operator.gt, ast.GtE: operator.ge,
              ast.Eq: operator.eq, ast.NotEq: operator.ne}


def _evaluate(node: ast.AST) -> float | bool:
    if isinstance(node, ast.Expression):
        return _evaluate(node.body)
    if isinstance(node, ast.Constant) and isinstance(node.value, (int, float)):
        return node.value
    if isinstance(node, ast.BoolOp):
        values = [_evaluate(v) for v in node.values]
        return all(values) if isinstance(node.op, ast.And) else any(values)
    if isinstance(node, ast.BinOp) and type(node.op) in _OPERATORS:
        return _OPERATORS[type(node.op)](_evaluate(node.left), _evaluate(node.right))
    if isinstance(node, ast.UnaryOp) and type(node.op) in _OPERATORS:
        return _OPERATORS[type(node.op)](_evaluate(node.operand))
    if isinstance(node, ast.Compare):
        left = _evaluate(node.left)
        for op, right_node in zip(node.ops, node.comparators):
            right = _evaluate(right_node)
            if not _OPERATORS[type(op)](left, right):
                return False
            left = right
        return True
    raise ValueError(f"unsupported expression {ast.dump(node)}")


def refused(rule: Rule, values: Mapping[str, float]) -> bool:
    """Whether `rule` refuses these (numeric) values; LIGGGHTS' boolean syntax mapped to Python."""
    text = re.sub(r"\$\((.*?)\)", r"(\1)", rule.condition)
    text = re.sub(r"\$\{(\w+)\}|v_(\w+)", lambda m: repr(values[m.group(1) or m.group(2)]), text)
    text = text.replace("&&", " and ").replace("||", " or ").replace("!=", "<>")
    text = text.replace("!", " not ").replace("<>", "!=")
    return bool(_evaluate(ast.parse(text, mode="eval")))


def check_values(values: Mapping[str, object], case: str, given: Iterable[str] = ()) -> None:
    """Apply the case's rules to the values (defaults overridden by the runner's and the user's).
    A value the user gave must be a number wherever a rule uses it; a rule whose default is not a
    plain number (a formula of other variables) is left to LIGGGHTS."""
    given = set(given)
    numbers: dict[str, float] = {}
    for name, value in values.items():
        text = str(value).strip()
        if _NUMBER.match(text):
            numbers[name] = float(text)
    for rule in rules(case):
        names = rule.names()
        for name in names & given:
            if name not in numbers:
                raise ParameterError(f"-v {name} {values[name]}: not a number ({rule.message.split(':', 1)[-1].strip()})")
        if names <= numbers.keys() and refused(rule, numbers):
            message = re.sub(r"\$\{(\w+)\}", lambda m: str(values[m.group(1)]), rule.message)
            message = re.sub(r"\$\((.*?)\)", lambda m: f"{eval_immediate(m.group(1), numbers):g}", message)
            raise ParameterError(message)


def eval_immediate(expression: str, numbers: Mapping[str, float]) -> float:
    text = re.sub(r"v_(\w+)", lambda m: repr(numbers[m.group(1)]), expression)
    return float(_evaluate(ast.parse(text, mode="eval")))
