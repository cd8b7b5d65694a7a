"""Where PyPI's xacro (its 2.x releases, ROS 2's) differs from noetic's xacro 1.14, set right
through xacro's own module API, so a ROS 1 robot description gives ROS 1's output.

minros keeps PyPI's xacro rather than a xacro of its own: it is ROS's code, maintained, and
apart from what is here it processes ROS 1 files as 1.14 does (its other changes add units,
``bool``/``vars`` and ``$(cwd)``'s root). The differences a ROS 1 file meets:

- Namespaced includes (``<xacro:include filename="arm.xacro" ns="arm"/>``): 1.14 evaluates a
  call of ``xacro:arm.link``, its arguments, block parameters and defaults included, in the
  ``arm`` namespace's scope (``size:=${len}`` or ``size="${len}"`` is arm's ``len``); 2.x
  evaluates the arguments in the caller's. :func:`apply` wraps ``handle_macro_call`` so that
  a namespaced call looks names up in the namespace's properties first, which is 1.14's rule
  (a namespace's table looks in its parent, so the including file's names resolve too), then
  in the caller's scope, where 1.14 would have failed ("name is not defined") and 2.x
  succeeds: a file noetic processes gives noetic's output, one it rejects gives 2.x's.
- ``$(find pkg)`` of a package that is not there: 1.14 says ``resource not found: pkg`` with
  the ROS package path, as roslaunch's substitution does; 2.x prints the exception's class.
"""

from __future__ import annotations

from typing import Any

from minros import packages


def apply(xacro: Any) -> None:
    """Give the imported ``xacro`` module noetic's behaviour (once)."""
    if getattr(xacro, "_minros_noetic", False):
        return
    handle_macro_call = xacro.handle_macro_call
    eval_extension = xacro.eval_extension

    class NoeticScope(xacro.Table):
        """A namespaced call's scope: the namespace's properties first (1.14's rule), then
        the caller's, so a name 1.14 could not see (a parameter of an enclosing macro) still
        resolves as 2.x resolves it instead of failing as in 1.14."""

        def __init__(self, namespace: Any, caller: Any) -> None:
            super().__init__(namespace)
            self.caller = caller

        def __getitem__(self, key: str) -> Any:
            try:
                return super().__getitem__(key)
            except KeyError:
                return self.caller[key]

        def __contains__(self, key: object) -> bool:
            return super().__contains__(key) or key in self.caller

    def noetic_macro_call(node: Any, macros: Any, symbols: Any) -> Any:
        tag = node.tagName
        if tag.startswith("xacro:") and tag != "xacro:call":
            try:
                _macros, scope, _macro = xacro.resolve_macro(tag[len("xacro:"):], macros, symbols)
            except KeyError:
                pass  # not a macro: xacro's own call reports it
            else:
                if scope is not symbols:  # a namespaced macro
                    symbols = NoeticScope(scope, symbols)
        return handle_macro_call(node, macros, symbols)

    def noetic_eval_extension(text: str) -> Any:
        try:
            return eval_extension(text)
        except xacro.XacroException as exc:
            missing = getattr(exc.exc, "package_name", None)
            if missing is None:
                raise
            import rospkg

            where = [str(p) for p in packages.ros_package_path() + packages.BUILTIN_SHARE_DIRS]
            raise xacro.XacroException(
                "resource not found:", exc=rospkg.ResourceNotFound(missing, ros_paths=where)) from None

    xacro.handle_macro_call = noetic_macro_call
    xacro.eval_extension = noetic_eval_extension
    xacro._minros_noetic = True
