#!/usr/bin/env python3
"""Every section the sources cite exists: a citation of README.md or a docs/NAME.md followed by a
quoted title, in the code, tests, scripts and documents, names a title found in that document
(whitespace and line breaks aside), and every docs/NAME.md cited is in the repository. The code cites measurements by
the bold titles of README.md and docs/transient_measurements.md; a title renamed or moved must
take its citations along.

Usage: citations_test.py SOURCE_DIR. Exit status 1 with the unresolved citations listed."""
import os
import re
import sys

CITATION = re.compile(
    r'(README|docs/[A-Za-z_]+\.md)'           # the document
    r'((?:[ \t]*\n?[ \t]*(?://|#)?[ \t]*)?)'  # a line break in a comment between it and the title
    r'\\?"((?:[^"\\\n]|\n[ \t]*(?://|#)?[ \t]*)+?)\\?"')
SCANNED = ('core', 'optimizer', 'tests', 'scripts', 'docs', 'studies')
SUFFIXES = ('.cpp', '.hpp', '.md', '.json', '.py', '.txt', '')


def flat(text):
    return re.sub(r'\s+', ' ', text)


def title_of(raw):
    return flat(raw.replace('//', ' ').replace('#', ' ')).strip()


def unresolved(root, files):
    """(file, document, title) of each citation whose title its document does not hold."""
    documents = {}
    found = []
    for path in files:
        try:
            with open(os.path.join(root, path), encoding='utf-8') as f:
                text = f.read()
        except (UnicodeDecodeError, OSError):
            continue
        for m in CITATION.finditer(text):
            name = 'README.md' if m.group(1) == 'README' else m.group(1)
            if name not in documents:
                try:
                    with open(os.path.join(root, name), encoding='utf-8') as f:
                        documents[name] = flat(f.read())
                except OSError:
                    documents[name] = None
            title = title_of(m.group(3))
            if documents[name] is None or title not in documents[name]:
                found.append((path, name, title))
    return found


def sources(root):
    out = ['README.md']
    for top in SCANNED:
        for d, dirs, names in os.walk(os.path.join(root, top)):
            dirs[:] = [x for x in dirs if x not in ('corpus', 'build')]
            for n in names:
                if os.path.splitext(n)[1] in SUFFIXES:
                    out.append(os.path.relpath(os.path.join(d, n), root))
    return out


def main():
    root = sys.argv[1]
    # The check itself: a made-up citation is caught, a real one is not.
    probe = os.path.join(os.environ.get('TMPDIR', '/tmp'), 'beamrail_citations_probe.txt')
    with open(probe, 'w', encoding='utf-8') as f:
        f.write('// README "No such section anywhere" and README "Guarantees"\n'
                '// docs/transient_measurements.md\n// "Mechanisms verify themselves"\n')
    caught = unresolved(root, [probe])
    os.remove(probe)
    if [t for _, _, t in caught] != ['No such section anywhere']:
        print('the check does not tell a made-up citation from real ones:', caught)
        return 1
    files = [p for p in sources(root) if p != os.path.relpath(__file__, root)]
    bad = unresolved(root, files)
    print(f'{len(files)} files scanned, {len(bad)} unresolved citations')
    for path, name, title in bad:
        print(f'  {path}: {name} "{title}"')
    return 1 if bad else 0


if __name__ == '__main__':
    sys.exit(main())
