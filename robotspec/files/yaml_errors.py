"""A YAML parser's error as a located error, worded the same whichever parser found it.

Why: PyYAML parses with libyaml when it was built with it (ten times faster) and in Python
otherwise; the two say the same things differently ("did not find expected key" against
"expected <block end>, but found '<scalar>'"). robotspec reads each file once, with the faster
parser, so instead of parsing again in Python for its wording, both parsers' messages are put in
one wording here, and what stands at the error's place is read from the text itself.
"""

from __future__ import annotations

import re

import yaml

from robotspec.errors import RobotSpecError
from robotspec.files.limits import env_name

__all__ = ["nesting_error", "parse_error", "unicode_error"]

# (context or None, pattern over the parser's problem) -> the common wording; ``{found}``
# becomes what the text holds at the error's place.
_EXPECTED = " or less indentation, but found {found}"
_WORDING: tuple[tuple[str | None, re.Pattern[str], str], ...] = tuple(
    (context, re.compile(pattern), text)
    for context, pattern, text in (
        (None, r"^mapping values are not allowed", "mapping values are not allowed here"),
        (None, r"^mapping keys are not allowed", "mapping keys are not allowed here"),
        (
            None,
            r"^(block )?sequence entries are not allowed",
            "sequence entries are not allowed here",
        ),
        (
            "while parsing a block mapping",
            r"^(did not find expected key|expected <block end>)",
            "expected a key of this mapping" + _EXPECTED,
        ),
        (
            "while parsing a block collection",
            r"^(did not find expected '-' indicator|expected <block end>)",
            "expected '- ' (another item)" + _EXPECTED,
        ),
        (None, r"^(did not find )?expected ',' or '\]'", "expected ',' or ']', but found {found}"),
        (None, r"^(did not find )?expected ',' or '\}'", "expected ',' or '}', but found {found}"),
        (
            None,
            r"^(did not find expected node content|expected the node content)",
            "expected a value, but found {found}",
        ),
        (
            None,
            r"^(did not find expected <document start>|expected '<document start>')",
            "expected '---' (a new document), but found {found}",
        ),
        (
            None,
            r"^found character .*that cannot start any token",
            "found character {char} that cannot start any token",
        ),
        (
            None,
            r"^did not find expected alphabetic or numeric character|^expected alphabetic or "
            r"numeric character",
            "expected a letter or digit, but found {found}",
        ),
        (
            None,
            r"^did not find expected comment or line break|^expected a comment or a line break",
            "expected a comment or the end of the line, but found {found}",
        ),
        (None, r"^found duplicate %?YAML directive", "found a second %YAML directive"),
    )
)

_BREAK = "\r\n\x85\u2028\u2029"
_WORD = re.compile(r"[^\s,\[\]{}]{1,20}")


def parse_error(exc: yaml.YAMLError, text: str, file: str) -> RobotSpecError:
    """``exc``, raised while reading ``text``, as ``file:line:col: invalid YAML: ...``."""
    if isinstance(exc, yaml.reader.ReaderError):
        return _character_error(text, exc.position, file)
    if not isinstance(exc, yaml.MarkedYAMLError):
        return RobotSpecError(f"invalid YAML: {exc}", file=file)
    mark = exc.problem_mark or exc.context_mark
    problem = exc.problem or exc.context or "invalid YAML"
    if mark is None:
        return RobotSpecError(f"invalid YAML: {problem}", file=file)
    index = _index(text, mark)
    line, column = mark.line + 1, mark.column + 1
    if problem.startswith("found unknown escape character"):
        if text[index : index + 1] == "\\":  # libyaml points at the backslash, Python after it
            index, column = index + 1, column + 1
        problem = f"found unknown escape character {_char(text, index)}"
    else:
        problem = _worded(exc.context, problem, text, index)
    return RobotSpecError(f"invalid YAML: {problem}", file=file, line=line, column=column)


def unicode_error(exc: UnicodeEncodeError, text: str, file: str) -> RobotSpecError:
    """A text libyaml cannot take (a lone surrogate), located as Python's reader locates it."""
    return _character_error(text, exc.start, file)


def nesting_error(
    text: str, start: int, depth: int, cap: int, file: str, exc: yaml.MarkedYAMLError
) -> RobotSpecError:
    """The depth cap's error where libyaml stopped at its own nesting limit first.

    ``start``: where the events read so far end, ``depth``: how deep they reached. The flow
    brackets after ``start`` (libyaml stops only on a dense run of them, within the 1,024
    characters it looks ahead) are counted to the one past the cap; if the count does not get
    there (a mix the count does not follow), libyaml's own place is given.
    """
    index = _past_cap(text, start, depth, cap)
    mark = exc.problem_mark
    if index is None:
        line, column = (None, None) if mark is None else (mark.line + 1, mark.column + 1)
    else:
        line, column = _line_column(text, index)
    return RobotSpecError(
        f"YAML nested too deeply (more than {cap} levels; "
        f"set {env_name('max_yaml_depth')} to raise it)",
        file=file,
        line=line,
        column=column,
    )


def _past_cap(text: str, start: int, depth: int, cap: int) -> int | None:
    """The index of the flow bracket that opens level ``cap + 1``, counting from ``start``."""
    quote = ""
    i = start
    end = min(len(text), start + 4096)
    while i < end:
        ch = text[i]
        if quote:
            if ch == "\\" and quote == '"':
                i += 1
            elif ch == quote:
                quote = ""
        elif ch in "'\"":
            quote = ch
        elif ch in "[{":
            depth += 1
            if depth > cap:
                return i
        elif ch in "]}":
            depth -= 1
        elif ch == "#" and (i == 0 or text[i - 1] in " \t\n"):
            newline = text.find("\n", i)
            i = end if newline < 0 else newline
        i += 1
    return None


def _line_column(text: str, index: int) -> tuple[int, int]:
    """1-based line and column of ``index`` (YAML's line breaks: LF, CR LF, CR, NEL, LS, PS)."""
    line = 1 + sum(text.count(b, 0, index) for b in "\n\x85\u2028\u2029")
    line += text.count("\r", 0, index) - text.count("\r\n", 0, index)
    start = max(text.rfind(b, 0, index) for b in _BREAK) + 1
    return line, index - start + 1


def _character_error(text: str, index: int, file: str) -> RobotSpecError:
    line, column = _line_column(text, index)
    return RobotSpecError(
        f"invalid YAML: character {_char(text, index)} is not allowed (control characters and "
        "lone surrogates are not YAML text)",
        file=file,
        line=line,
        column=column,
    )


def _worded(context: str | None, problem: str, text: str, index: int) -> str:
    for where, pattern, wording in _WORDING:
        if (where is None or where == context) and pattern.search(problem):
            found = _found(text, index) if "{found}" in wording else ""
            return wording.replace("{found}", found).replace("{char}", _char(text, index))
    return problem


def _index(text: str, mark: yaml.Mark) -> int:
    """The character offset of ``mark`` in ``text`` (both parsers count characters)."""
    return min(max(mark.index, 0), len(text))


def _char(text: str, index: int) -> str:
    if index >= len(text):
        return "'<end of file>'"
    ch = text[index]
    if ch.isprintable() and ch not in "'\\":
        return f"'{ch}'"
    if ch in "\t\n\r":
        return repr(ch)
    return f"'\\x{ord(ch):02x}'" if ord(ch) < 0x100 else f"'\\u{ord(ch):04x}'"


def _found(text: str, index: int) -> str:
    """What the text holds at ``index``, as a reader would name it."""
    if index >= len(text):
        return "the end of the file"
    ch = text[index]
    if ch in _BREAK:
        return "the end of the line"
    if ch in " \t":
        return "a tab" if ch == "\t" else "a space"
    word = _WORD.match(text, index)
    if word is None:
        return _char(text, index)
    found = word.group()
    if len(found) > 1 and found.endswith(":"):
        found = found[:-1]
    return f"'{found}'"
