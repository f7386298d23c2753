#!/usr/bin/env python3
"""The house rules of common/mpm, checked (ctest: Layout.*; .ci/run via make test).

  includes   every folder of common/mpm has a README.md whose line `may include: a, b` names the
             folders its files may include besides their own; an include of any other folder
             (a higher one, or a sibling) fails, naming the file, the line and the folder.
  sizes      no file in common/ over 800 lines; no function over 120 lines (a function is a
             brace block whose head ends in a parameter list, outside other functions).
  format     every tracked .cpp/.hpp is in the .clang-format style (clang-format --dry-run).

Usage: check_layout.py ROOT {includes,sizes,format}   exit 0 clean, 1 with the findings listed.
"""
import os, re, subprocess, sys

MAX_FILE_LINES = 800
MAX_FUNCTION_LINES = 120


def folders(mpm):
    out = {}
    for dp, _, fn in os.walk(mpm):
        if any(f.endswith(('.cpp', '.hpp', '.in')) for f in fn):
            rel = os.path.relpath(dp, mpm)
            out[rel] = [os.path.join(dp, f) for f in sorted(fn) if f.endswith(('.cpp', '.hpp'))]
    return out


def allowed(mpm, folder):
    readme = os.path.join(mpm, folder, 'README.md')
    if not os.path.isfile(readme):
        return None
    for line in open(readme, encoding='utf-8'):
        m = re.match(r'\s*may include:\s*(.*)$', line, re.I)
        if m:
            names = [s.strip(' `.') for s in m.group(1).split(',')]
            return {n for n in names if n and n != 'nothing'}
    return None


def check_includes(root):
    mpm = os.path.join(root, 'common', 'mpm')
    found = []
    tree = folders(mpm)
    for folder, files in sorted(tree.items()):
        ok = allowed(mpm, folder)
        if ok is None:
            found.append(f'common/mpm/{folder}/README.md: missing, or without a "may include:" line')
            continue
        for n in ok:
            if n not in tree:
                found.append(f'common/mpm/{folder}/README.md: may include unknown folder "{n}"')
        for path in files:
            for k, line in enumerate(open(path, encoding='utf-8'), 1):
                m = re.match(r'\s*#\s*include\s*"mpm/(.+)/[^/]+"', line)
                if not m:
                    continue
                target = m.group(1)
                if target == folder or target in ok:
                    continue
                found.append(f'{os.path.relpath(path, root)}:{k}: includes mpm/{target}/, which '
                             f'common/mpm/{folder}/README.md does not allow (may include: '
                             f'{", ".join(sorted(ok)) or "nothing"})')
    return found


def strip(text):
    """Source with comments and string/char literals blanked, lines kept."""
    text = re.sub(r'/\*.*?\*/', lambda m: re.sub(r'[^\n]', ' ', m.group(0)), text, flags=re.S)
    text = re.sub(r'R"(\w*)\(.*?\)\1"', lambda m: re.sub(r'[^\n]', ' ', m.group(0)), text, flags=re.S)
    out = []
    for line in text.split('\n'):
        line = re.sub(r'"(\\.|[^"\\])*"', '""', line)
        line = re.sub(r"'(\\.|[^'\\])*'", "''", line)
        out.append(re.sub(r'//.*', '', line))
    return out


HEAD_FN = re.compile(r'\)\s*(const|override|noexcept|final|mutable|&|->\s*[\w:<>,\s*&]+|\s)*$')
HEAD_CTL = re.compile(r'\b(if|for|while|switch|catch)\s*\(')
HEAD_LAMBDA = re.compile(r'\]\s*(\([^()]*\))?\s*(mutable|->\s*[\w:<>,\s*&]+|\s)*$')


def functions(path):
    lines = strip(open(path, encoding='utf-8').read())
    stack, out = [], []
    for k, line in enumerate(lines):
        for j, ch in enumerate(line):
            if ch == '{':
                head = ' '.join(lines[max(0, k - 4):k]) + ' ' + line[:j]
                head = re.split(r'[;{}]', head)[-1].strip()
                is_fn = bool(HEAD_FN.search(head)) and not HEAD_CTL.match(head.lstrip()) \
                    and not HEAD_LAMBDA.search(head) and '=' not in head.split('(')[0]
                stack.append((k, is_fn))
            elif ch == '}' and stack:
                start, is_fn = stack.pop()
                if is_fn and not any(f for _, f in stack):
                    out.append((k - start + 1, start + 1))
    return out


def check_sizes(root):
    found = []
    for dp, _, fn in os.walk(os.path.join(root, 'common')):
        for f in sorted(fn):
            if not f.endswith(('.cpp', '.hpp')):
                continue
            path = os.path.join(dp, f)
            n = sum(1 for _ in open(path, encoding='utf-8'))
            if n > MAX_FILE_LINES:
                found.append(f'{os.path.relpath(path, root)}: {n} lines (at most {MAX_FILE_LINES})')
    for top in ('common', 'mpm-prep', 'mpm-run', 'mpm-post'):
        for dp, _, fn in os.walk(os.path.join(root, top)):
            for f in sorted(fn):
                if f.endswith(('.cpp', '.hpp')):
                    path = os.path.join(dp, f)
                    for n, line in functions(path):
                        if n > MAX_FUNCTION_LINES:
                            found.append(f'{os.path.relpath(path, root)}:{line}: a function of {n} '
                                         f'lines (at most {MAX_FUNCTION_LINES})')
    return found


def check_format(root):
    files = subprocess.run(['git', 'ls-files', '*.cpp', '*.hpp'], cwd=root, capture_output=True,
                           text=True, check=True).stdout.split()
    r = subprocess.run(['clang-format', '--dry-run', '--Werror'] + files, cwd=root,
                       capture_output=True, text=True)
    bad = sorted({m.group(1) for m in re.finditer(r'^(\S+?):\d+:\d+: error', r.stderr, re.M)})
    return [f'{b}: not in the .clang-format style (make format fixes it)' for b in bad] + \
        ([r.stderr.strip()] if r.returncode and not bad else [])


if __name__ == '__main__':
    root, what = sys.argv[1], sys.argv[2]
    found = {'includes': check_includes, 'sizes': check_sizes, 'format': check_format}[what](root)
    for f in found:
        print(f)
    print(f'{what}: {len(found)} finding(s)' if found else f'{what}: clean')
    sys.exit(1 if found else 0)
