"""Build helpers of the documentation site (mkdocs.yml names them; not a page).

- ``on_page_markdown``, an MkDocs hook: the guide page (guide.md) is the README, its links
  made relative to docs/; the reference's first page lists the names of ``ecofmaps``, each
  linked to its entry in its package's page.
- ``RuntimeDocstrings``, a Griffe extension: the docstring a function has at run time. Griffe
  unwraps a decorated function and reads the docstring of the function inside, which is empty
  where the docstring is set on the wrapper afterwards (``energy_cof.__doc__ = ...``).
"""

import inspect
import re
import sys
import textwrap
from pathlib import Path

import griffe

README = Path(__file__).resolve().parents[1] / "README.md"


#: Where the reference's first page lists the names of ``ecofmaps``.
NAMES = "<!-- the names of ecofmaps: docs/site_hooks.py writes them here -->"


def on_page_markdown(markdown, page, **kwargs):
    """The README's text for guide.md, the names of ``ecofmaps`` in reference/index.md."""
    if page.file.src_uri == "guide.md":
        text = re.sub(r"\A# .*", "# Guide (the README)", README.read_text(encoding="utf-8"))
        return re.sub(r"\]\(docs/", "](", text)
    if page.file.src_uri == "reference/index.md":
        return markdown.replace(NAMES, _names_of_ecofmaps())
    return markdown


def _names_of_ecofmaps():
    """A table of each name of ``ecofmaps`` linked to its entry in its package's page, and the
    entry itself of a name that no public package holds."""
    import ecofmaps

    rows, entries = ["| name | documented as |", "|---|---|"], []
    for module, names in sorted(ecofmaps._PUBLIC.items()):
        package = ".".join(module.split(".")[:2])
        for name in names:
            if package.startswith("ecofmaps._"):
                entries.append(f"::: ecofmaps.{name}")
            else:
                rows.append(f"| `{name}` | [`{package}.{name}`][{package}.{name}] |")
    return "\n".join([*rows, "", *entries])


#: reStructuredText roles in docstrings (:func:`name`, :math:`x`), shown as code in Markdown.
ROLE = re.compile(r":(?:func|class|mod|meth|attr|data|exc|obj|math):`~?([^`]+)`")
#: A reStructuredText ``.. math::`` directive and the lines indented under it.
MATH = re.compile(r"^( *)\.\. math::[ \t]*(.*)\n((?:\1[ \t]+\S.*\n|[ \t]*\n)*)", re.MULTILINE)


def _markdown(text):
    """A docstring's reStructuredText roles as code spans, its math directives as code blocks."""

    def block(match):
        indent, first, rest = match.groups()
        lines = [first.strip(), *textwrap.dedent(rest).strip().splitlines()]
        body = "\n".join(indent + line for line in lines if line)
        return f"{indent}```text\n{body}\n{indent}```\n\n"

    return ROLE.sub(r"`\1`", MATH.sub(block, text + "\n")).rstrip("\n")


def _source_comment(path, name):
    """The ``#:`` comment lines just above ``name = ...`` in the file ``path``, or None."""
    lines = Path(path).read_text(encoding="utf-8").splitlines()
    for number, line in enumerate(lines):
        if re.match(rf"{re.escape(name)}\s*(:[^=]*)?=", line):
            comment = []
            while number and lines[number - 1].startswith("#:"):
                number -= 1
                comment.insert(0, lines[number][2:].strip())
            return " ".join(comment) or None
    return None


class RuntimeDocstrings(griffe.Extension):
    """Each public object's docstring as Python and the source hold it.

    - A function takes the docstring it has at run time.
    - A constant takes its ``#:`` comment, not the docstring of its type (``dict.__doc__``),
      looked up in its module and, for a name imported on first use, in the module that
      defines it (the package's ``_PUBLIC``).
    - reStructuredText roles become code spans, math directives code blocks.
    """

    def on_instance(self, *, node, obj, agent, **kwargs):
        if not isinstance(node, griffe.ObjectNode) or node.parent is None:
            return
        text = obj.docstring.value if obj.docstring else None
        if obj.is_function and text is None:
            text = getattr(getattr(node.parent.obj, node.name, None), "__doc__", None)
        elif obj.is_attribute:
            text = self._constant_comment(node)
        if text:
            obj.docstring = griffe.Docstring(
                _markdown(inspect.cleandoc(text)),
                parent=obj,
                parser=agent.docstring_parser,
                parser_options=agent.docstring_options,
            )
        else:
            obj.docstring = None

    def on_class_members(self, *, node, cls, **kwargs):
        """A class without the attributes Python gives every class (``__doc__``, ...) nor the
        special methods a dataclass writes (no docstring), and a named tuple without its
        fields' accessors (its docstring lists the fields)."""
        fields = getattr(node.obj, "_fields", ()) if isinstance(node, griffe.ObjectNode) else ()
        for name, member in list(cls.members.items()):
            if member.is_alias:
                continue
            special = name.startswith("__") and name != "__init__"
            if (special and (member.is_attribute or member.docstring is None)) or name in fields:
                del cls.members[name]

    @staticmethod
    def _constant_comment(node):
        module = node.parent.obj
        homes = [module.__name__] if inspect.ismodule(module) else []
        public = getattr(module, "_PUBLIC", {})
        homes += [home for home, names in public.items() if node.name in names]
        for home in homes:
            path = getattr(sys.modules.get(home), "__file__", None)
            comment = path and _source_comment(path, node.name)
            if comment:
                return comment
        return None
