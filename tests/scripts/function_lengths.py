#!/usr/bin/env python3
"""Function lengths of rbx's C++ sources (engine/, reference/, comparisons/).

Usage: function_lengths.py ROOT [LIMIT] [TOP]
Prints the TOP longest functions (default 10), "lines file:line signature", and exits 1 when
one of them has LIMIT lines or more (default 120). A function is a brace block whose head ends
in a parameter list (not if/for/while/switch/catch, not a lambda); its lines run from the line
of its opening brace to that of its closing one. Comments, string and raw-string literals are
blanked first so that their braces do not count.
"""
import glob
import os
import re
import sys


def blank_literals(src):
    """The source with comments and literals replaced by blanks, newlines kept."""
    out, i, n = [], 0, len(src)
    while i < n:
        if src.startswith('//', i):
            j = src.find('\n', i)
            i = n if j < 0 else j
            continue
        if src.startswith('/*', i):
            j = src.find('*/', i + 2)
            out.append('\n' * src.count('\n', i, j + 2))
            i = j + 2
            continue
        m = re.match(r'R"([^(\s]*)\(', src[i:])
        if m and (i == 0 or not (src[i - 1].isalnum() or src[i - 1] == '_')):
            end = ')' + m.group(1) + '"'
            j = src.find(end, i + m.end())
            out.append('""' + '\n' * src.count('\n', i, j + len(end)))
            i = j + len(end)
            continue
        c = src[i]
        if c in '"\'':
            j = i + 1
            while j < n and src[j] != c:
                j += 2 if src[j] == '\\' else 1
            out.append(c + c)
            i = j + 1
            continue
        out.append(c)
        i += 1
    return ''.join(out)


CONTROL = re.compile(r'(^|[^\w])(if|for|while|switch|catch)\s*\(.*\)\s*$')
FUNCTION_HEAD = re.compile(
    r'\)\s*(const)?\s*(noexcept)?\s*(override)?\s*(->[^{;]*)?$|\)\s*:\s*\w.*$')
LAMBDA_HEAD = re.compile(r'\[[^\]]*\]\s*(\([^)]*\))?\s*(mutable)?\s*(->[^{]*)?$')


def functions(path):
    """(lines, line, head) of every outermost function body in the file."""
    src = blank_literals(open(path, encoding='utf-8').read())
    found, stack, line, last = [], [], 1, 0
    for i, c in enumerate(src):
        if c == '\n':
            line += 1
        elif c == '{':
            head = ' '.join(src[last:i].split())
            kind = 'block'
            if FUNCTION_HEAD.search(head) and not CONTROL.search(head):
                kind = 'function'
            if LAMBDA_HEAD.search(head):
                kind = 'lambda'
            if any(k == 'function' for k, _, _ in stack):
                kind = 'inner'
            stack.append((kind, line, head))
            last = i + 1
        elif c == '}':
            if stack:
                kind, start, head = stack.pop()
                if kind == 'function':
                    found.append((line - start + 1, start, head[-70:]))
            last = i + 1
        elif c == ';':
            last = i + 1
    return found


def main():
    root = sys.argv[1]
    limit = int(sys.argv[2]) if len(sys.argv) > 2 else 120
    top = int(sys.argv[3]) if len(sys.argv) > 3 else 10
    rows = []
    for folder in ('engine', 'reference', 'comparisons'):
        for path in sorted(glob.glob(os.path.join(root, folder, '**', '*.cpp'), recursive=True) +
                           glob.glob(os.path.join(root, folder, '**', '*.h'), recursive=True)):
            rel = os.path.relpath(path, root)
            rows += [(n, rel, at, head) for n, at, head in functions(path)]
    rows.sort(key=lambda r: (-r[0], r[1], r[2]))
    for n, rel, at, head in rows[:top]:
        print(f'{n:4d} {rel}:{at} {head}')
    over = [r for r in rows if r[0] >= limit]
    if over:
        print(f'{len(over)} functions of {limit} lines or more (split them into named stages)')
        return 1
    print(f'every function under {limit} lines ({len(rows)} functions)')
    return 0


if __name__ == '__main__':
    sys.exit(main())
