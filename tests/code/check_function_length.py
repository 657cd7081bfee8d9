#!/usr/bin/env python3
"""The project's rule: no function longer than 120 lines outside tests.

Scans the C, C++, OpenCL and GLSL sources of the product's directories (tests/ directories
anywhere are exempt) and prints every function whose body, from the first line of its
signature to its closing brace, is longer than the limit; exits 1 if there is one.

    check_function_length.py SOURCE_DIR [--limit N] [--all]

--all prints the length of every function (longest first), for finding what to split.

A lexer, not a compiler: comments, string and character literals (raw strings included) and
preprocessor lines are blanked, then braces are matched. A brace opens a function when the
text before it (since the last `;` or brace of a namespace, class or function) is a
signature: `name(...)` followed by qualifiers, a trailing return type or a constructor's
initialiser list. Namespaces, `extern "C"` and class bodies are looked into; lambdas and
local classes count as part of the function around them.
"""
import os
import re
import sys

SOURCE_DIRS = ["accel", "apps", "bench", "fuzz", "host", "kernels", "python", "robot",
               "shaders", "trials", "viewer"]
EXTENSIONS = (".cpp", ".cc", ".h", ".hpp", ".cl", ".comp", ".glsl")
EXEMPT_DIR_NAMES = {"tests", "corpus", "regressions"}
DEFAULT_LIMIT = 120

CONTROL = re.compile(r"^\s*(if|for|while|switch|catch|do|else|try)\b")
TYPE_SCOPE = re.compile(r"^\s*(\[\[[^\]]*\]\]\s*)*(class|struct|union)\b")
# A namespace may follow a macro that ends without a semicolon (FVP_KERNEL_CODE(name)).
NAMESPACE = re.compile(r"(^|[\s)])(inline\s+)?namespace(\s+[\w:]+)?\s*$|^\s*extern\s*\"\"\s*$")
# What may follow a signature's closing parenthesis before its body.
QUALIFIERS = re.compile(
    r"^(\s*(const|noexcept(\s*\([^()]*\))?|override|final|mutable|volatile|&&|&|"
    r"requires\b.*|->\s*[^{};=]+|try))*\s*$")
# A constructor's initialiser list: `) : member(x), other{y}`.
INIT_LIST = re.compile(r"\)\s*(noexcept\s*)?:\s*[^:].*[)}]\s*$", re.S)


def blank_literals(text):
    """Comments, literals and preprocessor lines as spaces; newlines kept (line numbers)."""
    out = []
    i, n = 0, len(text)
    line_start = True
    while i < n:
        c = text[i]
        if line_start and c in " \t":
            out.append(c)
            i += 1
            continue
        if line_start and c == "#":
            # A preprocessor line, with its continuations.
            while i < n and text[i] != "\n":
                if text[i] == "\\" and i + 1 < n and text[i + 1] == "\n":
                    out.append(" \n")
                    i += 2
                    continue
                out.append(" ")
                i += 1
            continue
        line_start = False
        if c == "\n":
            out.append(c)
            line_start = True
            i += 1
        elif text.startswith("//", i):
            while i < n and text[i] != "\n":
                out.append(" ")
                i += 1
        elif text.startswith("/*", i):
            end = text.find("*/", i + 2)
            end = n if end < 0 else end + 2
            out.append(re.sub(r"[^\n]", " ", text[i:end]))
            i = end
        elif c == "R" and i + 1 < n and text[i + 1] == '"' and (i == 0 or not (
                text[i - 1].isalnum() or text[i - 1] == "_") or text[i - 1] in "uU8L"):
            m = re.match(r'R"([^()\\ ]{0,16})\(', text[i:])
            if not m:
                out.append(c)
                i += 1
                continue
            close = ")" + m.group(1) + '"'
            end = text.find(close, i + m.end())
            end = n if end < 0 else end + len(close)
            out.append('""' + re.sub(r"[^\n]", " ", text[i + 2:end]))
            i = end
        elif c in "\"'":
            if c == "'" and i > 0 and text[i - 1].isalnum() and text[i + 1:i + 2].isalnum():
                out.append(" ")  # a digit separator: 1'000'000
                i += 1
                continue
            j = i + 1
            while j < n and text[j] != c and text[j] != "\n":
                j += 2 if text[j] == "\\" else 1
            out.append(c + " " * (j - i - 1) + c)
            i = j + 1
        else:
            out.append(c)
            i += 1
    return "".join(out)


def strip_template_prefix(header):
    header = header.lstrip()
    while header.startswith("template"):
        k = header.find("<")
        if k < 0:
            break
        depth = 0
        for j in range(k, len(header)):
            if header[j] == "<":
                depth += 1
            elif header[j] == ">":
                depth -= 1
                if depth == 0:
                    header = header[j + 1:].lstrip()
                    break
        else:
            break
    return header


def classify(header):
    """'scope' (looked into), 'function', or 'data' (a brace initialiser, enum, ...)."""
    h = strip_template_prefix(" ".join(header.split()))
    if NAMESPACE.search(h):
        return "scope"
    if TYPE_SCOPE.search(h) and "(" not in h.split("{")[0].split(":")[0]:
        return "scope"
    if re.match(r"^\s*enum\b", h) or CONTROL.search(h) or h.endswith("=") or not h:
        return "data"
    close = h.rfind(")")
    if close >= 0 and "(" in h and QUALIFIERS.match(h[close + 1:]):
        before = re.sub(r"\boperator\s*[^\s(]*", "operator", h[:h.find("(")])
        if "=" in before and "[" not in before:
            return "data"  # `x = f(a) {` is no C++; `auto f = [](...) {` is a function
        return "function"
    if INIT_LIST.search(h):
        return "function"
    return "data"


def functions_in(text):
    """(first line, last line, signature) of each outermost function of one file."""
    code = blank_literals(text)
    found = []
    # Each open brace: (kind, line of the signature's start, signature).
    stack = []
    header = []  # the text since the last boundary at a scope level
    header_line = None
    line = 1
    for c in code:
        if c == "\n":
            line += 1
        inside_function = any(kind != "scope" for kind, _, _ in stack)
        if inside_function:
            if c == "{":
                stack.append(("block", line, ""))
            elif c == "}":
                kind, start, signature = stack.pop()
                if kind == "function":
                    found.append((start, line, signature))
                    header, header_line = [], None
            continue
        if c == "{":
            signature = "".join(header)
            kind = classify(signature)
            if kind == "data":
                # Part of the statement: a member's brace initialiser may precede a body.
                stack.append(("data", line, ""))
                continue
            stack.append((kind, header_line or line, " ".join(signature.split())))
            header, header_line = [], None
        elif c == "}":
            kind, start, signature = stack.pop() if stack else ("scope", line, "")
            header, header_line = [], None
        elif c == ";":
            header, header_line = [], None
        else:
            if header_line is None and not c.isspace():
                header_line = line
            header.append(c)
    return found


def short_name(signature):
    m = re.search(r"([~\w:]+(?:operator\s*\S+?)?)\s*\(", signature)
    return m.group(1) if m else signature[:60]


def source_files(root):
    for top in SOURCE_DIRS:
        for dirpath, dirnames, filenames in os.walk(os.path.join(root, top)):
            dirnames[:] = sorted(d for d in dirnames if d not in EXEMPT_DIR_NAMES)
            for name in sorted(filenames):
                if name.endswith(EXTENSIONS):
                    yield os.path.join(dirpath, name)


def main(argv):
    args = [a for a in argv[1:] if not a.startswith("--")]
    limit = DEFAULT_LIMIT
    if "--limit" in argv:
        limit = int(argv[argv.index("--limit") + 1])
        args.remove(str(limit))
    if len(args) != 1:
        print(__doc__, file=sys.stderr)
        return 2
    root = args[0]
    rows = []
    for path in source_files(root):
        with open(path, encoding="utf-8", errors="replace") as f:
            text = f.read()
        for start, end, signature in functions_in(text):
            rows.append((end - start + 1, os.path.relpath(path, root), start,
                         short_name(signature)))
    rows.sort(key=lambda r: (-r[0], r[1], r[2]))
    shown = rows if "--all" in argv else [r for r in rows if r[0] > limit]
    for length, path, start, name in shown:
        print(f"{length:5d}  {path}:{start}  {name}")
    long_ones = [r for r in rows if r[0] > limit]
    print(f"{len(rows)} functions in {len(set(r[1] for r in rows))} files; "
          f"{len(long_ones)} longer than {limit} lines")
    return 1 if long_ones else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
