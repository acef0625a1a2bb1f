"""Every relative link and image in README.md, docs/**/*.md and studies/README.md resolves: the file
exists, and an anchor (`file.md#heading` or `#heading`) names a heading of that file (GitHub's
rule: lower case, punctuation dropped, spaces to hyphens, repeats numbered -1, -2, ...).
Links inside fenced code blocks and code spans are not links and are skipped."""
from __future__ import annotations

import os
import re
from pathlib import Path
from urllib.parse import unquote

ROOT = Path(os.environ.get("TSG_SOURCE_DIR", Path(__file__).resolve().parents[2]))

INLINE = re.compile(r"!?\[(?:[^\[\]]|\[[^\]]*\])*\]\(\s*<?([^)\s>]+)>?(?:\s+\"[^\"]*\")?\s*\)")
REFERENCE = re.compile(r"^\s{0,3}\[[^\]]+\]:\s*<?(\S*[./#]\S*?)>?(?:\s+\"[^\"]*\")?\s*$")  # [name]: path
IMG_TAG = re.compile(r"<img\s[^>]*src=\"([^\"]+)\"", re.IGNORECASE)
FENCE = re.compile(r"^\s*(```|~~~)")
CODE_SPAN = re.compile(r"(`+)(?:(?!\1).)+?\1")
HEADING = re.compile(r"^\s{0,3}(#{1,6})\s+(.*?)\s*#*\s*$")


def documents() -> list[Path]:
    found = [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]
    if (ROOT / "studies" / "README.md").is_file():
        found.append(ROOT / "studies" / "README.md")
    return found


def prose_lines(path: Path) -> list[tuple[int, str]]:
    """The lines outside fenced code blocks, with code spans blanked."""
    lines, fenced = [], False
    for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
        if FENCE.match(line):
            fenced = not fenced
            continue
        if not fenced:
            lines.append((number, CODE_SPAN.sub("", line)))
    return lines


def slug(heading: str) -> str:
    text = re.sub(r"!?\[([^\]]*)\]\([^)]*\)", r"\1", heading)   # a link in a heading counts by its text
    text = re.sub(r"<[^>]+>", "", text).strip().lower()
    return re.sub(r"[^\w\- ]", "", text).replace(" ", "-")


def anchors(path: Path) -> set[str]:
    seen: dict[str, int] = {}
    names = set()
    for _, line in prose_lines(path):
        match = HEADING.match(line)
        if not match:
            continue
        base = slug(match.group(2))
        count = seen.get(base, 0)
        seen[base] = count + 1
        names.add(base if count == 0 else f"{base}-{count}")
    names.update(re.findall(r"<a\s+(?:name|id)=\"([^\"]+)\"", path.read_text(encoding="utf-8")))
    return names


def links(path: Path) -> list[tuple[int, str]]:
    found = []
    for number, line in prose_lines(path):
        targets = INLINE.findall(line) + IMG_TAG.findall(line)
        reference = REFERENCE.match(line)
        if reference:
            targets.append(reference.group(1))
        found += [(number, target) for target in targets]
    return found


def broken(path: Path) -> list[str]:
    problems = []
    for number, target in links(path):
        if re.match(r"^[a-z][a-z0-9+.-]*:", target, re.IGNORECASE) or target.startswith("//"):
            continue                                              # http:, https:, mailto: ...
        file_part, _, anchor = target.partition("#")
        where = f"{path.relative_to(ROOT)}:{number}: {target}"
        resolved = (path.parent / unquote(file_part)).resolve() if file_part else path
        if file_part.startswith("/"):
            problems.append(f"{where} (absolute path)")
            continue
        if not resolved.exists():
            problems.append(f"{where} (no such file)")
            continue
        if anchor and resolved.suffix == ".md" and resolved.is_file() and unquote(anchor).lower() not in anchors(resolved):
            problems.append(f"{where} (no heading #{anchor} in {resolved.relative_to(ROOT)})")
    return problems


def test_slug_follows_github():
    assert slug("Squeezes on the paper machine") == "squeezes-on-the-paper-machine"
    assert slug("The tool: `tsg-accuracy` (cases/accuracy.py)") == "the-tool-tsg-accuracy-casesaccuracypy"
    assert slug("Periodic against full at 1 mm") == "periodic-against-full-at-1-mm"


def test_every_relative_link_resolves():
    problems = [problem for path in documents() for problem in broken(path)]
    assert not problems, "broken links:\n" + "\n".join(problems)


def test_documents_found():
    names = {path.name for path in documents()}
    assert "README.md" in names and len(names) > 5
