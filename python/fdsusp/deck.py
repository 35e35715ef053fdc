"""Namelist decks of fdsusp (doc/INPUT.md), written from Python values and read back.

    from fdsusp import deck
    text = deck.text([('domain', {'box': (8, 20, 8), 'cells_per_radius': 4, 'shear_rate': 1}),
                      ('time', {'dt': 2e-3}),
                      ('contact', {'friction': 0.5, 'implicit': None})],   # None: key left out
                     comment='a comment line')
    deck.write('deck.nml', text)
    groups = deck.parse(text)      # [('domain', {'box': [8, 20, 8], ...}), ...]

The one writer of the study scripts' decks: a group is '&name key = value, ... /' on one line
(broken between keys over WIDTH characters: fdsusp reads lines of at most 1024), keys in the order given (None leaves a key out, so that a deck holds only what differs from the
program's defaults); values: True/False as .true./.false., strings quoted ('' doubling a quote),
integers as written, floats as Python's shortest repr (0.002, 1e-05, 20.0: read back exactly),
sequences as comma-separated lists. parse() is a small reader of such decks (and of the shipped
ones: comments, several lines per group, array elements such as position(:,1) as keys).
"""


def value(v, float_format=None):
    """One namelist value (module doc); float_format ('%g', ...) rounds floats instead of their repr."""
    if isinstance(v, str):
        return "'%s'" % v.replace("'", "''")
    if isinstance(v, (list, tuple)):
        return ', '.join(value(x, float_format) for x in v)
    if type(v).__name__ in ('bool', 'bool_'):
        return '.true.' if v else '.false.'
    if isinstance(v, int) or type(v).__name__.startswith(('int', 'uint')):
        return str(int(v))
    if hasattr(v, 'tolist') and not isinstance(v, float) and getattr(v, 'ndim', 0) > 0:   # numpy arrays
        return value(v.tolist(), float_format)
    return float_format % float(v) if float_format else repr(float(v))


# fdsusp reads a deck line by line into 1024 characters (src/runtime/deck_text.F90 deck_line_length);
# a group longer than WIDTH is broken between its keys, continuation lines indented
WIDTH = 132


def group(name, settings, float_format=None):
    """'&name key = value, ... /' (keys whose value is None left out); over WIDTH characters, one
    line per key or per as many keys as fit (a namelist group may span lines)."""
    items = ['%s = %s' % (k, value(v, float_format)) for k, v in settings.items() if v is not None]
    line = '&%s %s /' % (name, ', '.join(items)) if items else '&%s /' % name
    if len(line) <= WIDTH:
        return line
    lines, cur = [], '&%s' % name
    for k, item in enumerate(items):
        piece = item + (',' if k < len(items) - 1 else ' /')
        if len(cur) + 1 + len(piece) > WIDTH and cur.strip() and cur != '&%s' % name:
            lines.append(cur)
            cur = ' ' * 2 + piece
        else:
            cur += ' ' + piece if cur.strip() else piece
    lines.append(cur)
    return '\n'.join(lines)


def text(groups, comment=None, float_format=None):
    """A deck: comment lines ('! ...'; a string or a list of them), then one line per group;
    groups: a list of (name, settings) or a dict {name: settings}. float_format: as value()'s
    (a study whose settings are rounded on purpose, e.g. '%g'; default: floats exactly)."""
    if isinstance(groups, dict):
        groups = list(groups.items())
    lines = []
    if comment is not None:
        lines += ['! ' + c for c in ([comment] if isinstance(comment, str) else comment)]
    lines += [group(n, s, float_format) for n, s in groups]
    return '\n'.join(lines) + '\n'


def write(path, deck_text):
    """Write a deck (its text) to path; returns path."""
    with open(path, 'w') as f:
        f.write(deck_text)
    return path


def _tokens(s):
    """s cut into values, keys and '=' at commas and blanks outside quotes and parentheses."""
    out, cur, quote, depth = [], '', None, 0
    for c in s + ' ':
        if quote:
            cur += c
            if c == quote:
                quote = None
        elif c in '\'"':
            quote = c
            cur += c
        elif c in '()':
            depth += 1 if c == '(' else -1
            cur += c
        elif depth == 0 and (c in ', \t=' or c == '/'):
            if cur:
                out.append(cur)
            cur = ''
            if c in '=/':
                out.append(c)
        else:
            cur += c
    return out


def _strip_comment(line):
    quote = None
    for i, c in enumerate(line):
        if quote:
            if c == quote:
                quote = None
        elif c in '\'"':
            quote = c
        elif c == '!':
            return line[:i]
    return line


def _scalar(tok):
    t = tok.strip()
    if len(t) >= 2 and t[0] == t[-1] and t[0] in '\'"':
        return t[1:-1].replace(t[0] * 2, t[0])
    low = t.lower()
    if low in ('.true.', 't', '.t.', 'true'):
        return True
    if low in ('.false.', 'f', '.f.', 'false'):
        return False
    try:
        return int(t)
    except ValueError:
        return float(low.replace('d', 'e'))


def parse(deck_text):
    """The groups of a deck: [(name, {key: value})], a value a scalar or a list of them; keys in
    lower case (namelists ignore case)."""
    toks = _tokens(' '.join(_strip_comment(l) for l in deck_text.splitlines()))
    groups, i = [], 0
    while i < len(toks):
        t = toks[i]
        if not t.startswith('&'):
            raise ValueError('expected a group (&name), found %r' % t)
        name, settings, key = t[1:].lower(), {}, None
        i += 1
        while i < len(toks) and toks[i] != '/':
            if i + 1 < len(toks) and toks[i + 1] == '=':
                key = toks[i].lower()
                settings[key] = []
                i += 2
                continue
            if key is None:
                raise ValueError('&%s: a value before any key: %r' % (name, toks[i]))
            settings[key].append(_scalar(toks[i]))
            i += 1
        if i >= len(toks):
            raise ValueError('&%s: no closing /' % name)
        i += 1
        groups.append((name, {k: v[0] if len(v) == 1 else v for k, v in settings.items()}))
    return groups
