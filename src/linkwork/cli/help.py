"""Help pages that read like a manual: no ``<bool>`` after a flag, no ``<list[str]>`` after a repeatable option.

typer prints a type placeholder after every option; for a flag (``--branches``) that is noise, and for a
repeatable option it prints the Python type (``<list[str]>``). :class:`Command` and :class:`Group` give flags no
placeholder, repeatable options the placeholder of one value (``<str>``; their help says "repeatable") and
arguments their name in capitals (``SPEC``), as Unix manuals do.
"""

from __future__ import annotations

from typing import Any

from typer.core import TyperArgument, TyperCommand, TyperGroup, TyperOption


def tidy_placeholders(params: list[Any]) -> list[Any]:
    """Set the help placeholder (metavar) of every parameter without one: nothing for a flag, one value's type
    for a repeatable option, the name in capitals for an argument."""
    for param in params:
        if param.metavar is not None:
            continue
        if isinstance(param, TyperArgument) and param.name:
            param.metavar = param.name.upper()
        elif isinstance(param, TyperOption):
            if param.is_flag or param.count:
                param.metavar = ""
            elif param.multiple:
                label = param.bare_type()
                if label.startswith("list[") and label.endswith("]"):
                    label = label[5:-1]
                param.metavar = f"<{label}>"
    return params


class Command(TyperCommand):
    """A typer command whose help shows no ``<bool>`` or ``<list[...]>`` placeholders."""

    def get_params(self, ctx: Any) -> list[Any]:
        return tidy_placeholders(super().get_params(ctx))


class Group(TyperGroup):
    """The ``linkwork`` group: commands listed in the order they were added, tidy placeholders."""

    def get_params(self, ctx: Any) -> list[Any]:
        return tidy_placeholders(super().get_params(ctx))

    def list_commands(self, ctx: Any) -> list[str]:
        return list(self.commands)
