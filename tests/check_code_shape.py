#!/usr/bin/env python3
"""The code-shape limits of docs/architecture.md, checked on the tree.

- no source file in engine/src over 600 lines;
- no function body in engine/src over 80 lines;
- the public Simulator header (engine/include/appell/simulator.hpp) at most 150 lines.

A function is found by a brace scan over the source with comments, string
and character literals blanked: a `{` whose preceding declaration ends in a
parameter list (or a constructor's initializer list) opens a function body
when it is not inside another function; namespace, class, struct, union and
enum bodies are scopes, not functions, and lambdas inside a function count
towards that function. The scanner's own cases run first (--self-test runs
only them): a check whose scanner misses an 81-line function would pass
whatever the tree holds.

Usage: check_code_shape.py [ROOT] [--self-test]
"""
import pathlib
import re
import sys

FILE_LIMIT, FUNCTION_LIMIT, HEADER_LIMIT = 600, 80, 150


def blank(text):
    """Comments and literals replaced by blanks, newlines kept."""
    out, i, n = [], 0, len(text)
    while i < n:
        if text.startswith('//', i):
            j = text.find('\n', i)
            i = n if j < 0 else j
            continue
        if text.startswith('/*', i):
            j = text.find('*/', i + 2)
            j = n if j < 0 else j + 2
            out.append('\n' * text.count('\n', i, j))
            i = j
            continue
        raw = re.match(r'R"([^(\s]*)\(', text[i:i + 20]) if text[i] == 'R' else None
        if raw and (i == 0 or not (text[i - 1].isalnum() or text[i - 1] == '_')):
            end = ')' + raw.group(1) + '"'
            j = text.find(end, i)
            j = n if j < 0 else j + len(end)
            out.append('""' + '\n' * text.count('\n', i, j))
            i = j
            continue
        c = text[i]
        if c in '"\'' and not (c == "'" and i > 0 and text[i - 1].isalnum()):  # 1'000 digit separators
            j = i + 1
            while j < n and text[j] != c and text[j] != '\n':
                j += 2 if text[j] == '\\' else 1
            out.append(c + c)
            i = j + 1
            continue
        out.append(c)
        i += 1
    return ''.join(out)


def functions(text):
    """(first line, lines, declaration tail) of every function body."""
    src = blank(text)
    stack, found, line, head_start = [], [], 1, 0
    for i, c in enumerate(src):
        if c == '\n':
            line += 1
        elif c in ';':
            head_start = i + 1
        elif c == '{':
            head = src[head_start:i].split('}')[-1].strip()
            head_start = i + 1
            inside_function = any(kind == 'fn' for kind, _, _ in stack)
            if inside_function:
                kind = 'block'
            elif re.search(r'\bnamespace\b', head) or head.startswith('extern'):
                kind = 'scope'
            elif re.search(r'\b(class|struct|union|enum)\b[^()]*$', head):
                kind = 'scope'
            elif re.search(r'\)\s*(const|noexcept|override|final|mutable|\s)*(->[^{]*)?$', head) or \
                    re.search(r'\)\s*:\s*\w', head):
                kind = 'fn'
            else:
                kind = 'block'  # an initializer, an array, a lambda outside a function
            stack.append((kind, line, head[-70:]))
        elif c == '}':
            head_start = i + 1
            if stack:
                kind, start, head = stack.pop()
                if kind == 'fn':
                    found.append((start, line - start + 1, head))
    return found


def self_test():
    body = '\n'.join('  x += %d;' % k for k in range(79))
    long_fn = 'namespace a {\nint f(int x) {\n' + body + '\n}\n}  // namespace a\n'
    cases = [
        (long_fn, [81]),
        (long_fn.replace('  x += 0;\n', ''), [80]),
        ('struct S {\n  int g() const {\n    return 1;\n  }\n};\n', [3]),
        ('S::S(int a)\n    : a_(a) {\n  f("{");\n  // }\n}\n', [4]),
        ('void h() {\n  auto l = [&](int k) {\n    return k;\n  };\n  char c = \'}\';\n}\n', [6]),
        ('const int table[] = {\n  1, 2,\n};\nenum class E { A, B };\n', []),
    ]
    for text, expected in cases:
        got = [n for _, n, _ in functions(text)]
        if got != expected:
            sys.exit('check_code_shape: the scanner is wrong on\n%s\nexpected %s, got %s' % (text, expected, got))


def main():
    args = [a for a in sys.argv[1:] if not a.startswith('--')]
    self_test()
    if '--self-test' in sys.argv:
        print('check_code_shape: scanner cases pass')
        return
    root = pathlib.Path(args[0] if args else pathlib.Path(__file__).resolve().parent.parent)
    problems = []
    for path in sorted((root / 'engine' / 'src').rglob('*')):
        if path.suffix not in ('.cpp', '.hpp'):
            continue
        text = path.read_text(encoding='utf-8')
        rel = path.relative_to(root)
        lines = text.count('\n')
        if lines > FILE_LIMIT:
            problems.append('%s: %d lines (at most %d per file)' % (rel, lines, FILE_LIMIT))
        for start, n, head in functions(text):
            if n > FUNCTION_LIMIT:
                problems.append('%s:%d: a function of %d lines (at most %d): %s' %
                                (rel, start, n, FUNCTION_LIMIT, ' '.join(head.split())))
    header = root / 'engine' / 'include' / 'appell' / 'simulator.hpp'
    lines = header.read_text(encoding='utf-8').count('\n')
    if lines > HEADER_LIMIT:
        problems.append('%s: %d lines (at most %d)' % (header.relative_to(root), lines, HEADER_LIMIT))
    if problems:
        sys.exit('check_code_shape: split these (docs/architecture.md, "Code shape"):\n  ' + '\n  '.join(problems))
    print('check_code_shape: engine/src within %d lines per file and %d per function' % (FILE_LIMIT, FUNCTION_LIMIT))


if __name__ == '__main__':
    main()
