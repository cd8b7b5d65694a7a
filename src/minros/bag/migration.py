"""rosbag's message migration: bring messages recorded under an older definition of a type
(another md5 sum, perhaps another type name) to the definition installed now.

Rules are classes deriving :class:`MessageUpdateRule` (from ``.bmr`` rule files, or the files
packages export with ``<rosbag migration_rule_file="..."/>``): each names an old and a new
type with their full definitions and updates one message to the next. The migrator orders a
type's rules into a chain (by ``order``, a rename rule last), bridges the gaps between them
and the installed definition with rules it generates (field by field, sub-messages through
paths of their own), and finds for each recorded type the path of rules to apply.
``check`` lists the paths and the generated rules that are not valid (a field that cannot be
matched); with ``-g`` it writes those rules to a file for a person to complete, which ``fix``
then loads. The path search follows ROS's rosbag, so the same bag and rules give the same
answers; generated rules are built as objects rather than by running generated source, so a
message definition read from a bag is never executed.
"""

from __future__ import annotations

import collections
import io
import itertools
import os
import sys
from typing import Any, Callable, Dict, Iterable, List, Optional, Sequence, Set, Tuple

from minros.msgs import UnknownTypeError, generate_dynamic, get_message_class
from minros.msgs.loader import is_builtin, parse_type

from .bag import Bag

__all__ = ["BagMigrationException", "MessageMigrator", "MessageUpdateRule", "RuleChain",
           "ScaffoldNode", "checkbag", "checkmessages", "clean_name", "constants_from_def",
           "fixbag", "fixbag2", "get_message_key", "get_path_key", "migration_default_value",
           "qualified_name"]


class BagMigrationException(Exception):
    """A migration that cannot be done (an invalid rule applied, no path, a rule file)."""


def _warn(text: str) -> None:
    print(text, file=sys.stderr)


def _system_class(type_name: str) -> Any:
    """The installed class of ``type_name``, or None."""
    try:
        return get_message_class(type_name)
    except (UnknownTypeError, LookupError, ValueError):
        return None


# ---------------------------------------------------------------------------------------------
# names and keys

def get_message_key(c: Any) -> Optional[Tuple[str, str]]:
    """``(type, md5sum)`` of a message class or instance: what identifies a definition."""
    try:
        return (c._type, c._md5sum)
    except AttributeError:
        return None


def get_path_key(c1: Any, c2: Any) -> Tuple[Any, Any]:
    """The key of the migration from ``c1`` to ``c2``."""
    return (get_message_key(c1), get_message_key(c2))


def clean_name(name: str, top_name: str) -> str:
    """``name`` without ``std_msgs`` and without the package of ``top_name``
    (``pkg/Sub`` inside ``pkg/Top`` -> ``Sub``)."""
    parts = name.split("/")
    for package in ("std_msgs", top_name.split("/")[0]):
        if package in parts:
            parts.remove(package)
    return "/".join(parts)


def qualified_name(name: str, top_name: str) -> str:
    """``name`` with its package (``Header`` -> ``std_msgs/Header``; a bare name takes the
    package of ``top_name``); built-in types as they are."""
    short = clean_name(name, top_name)
    if len(short.split("/")) == 2 or is_builtin(short):
        return short
    if short == "Header":
        return "std_msgs/Header"
    return top_name.split("/")[0] + "/" + short


def migration_default_value(field_type: str) -> str:
    """The Python expression a generated rule assigns to a field it cannot fill."""
    if field_type in ("bool", "byte", "int8", "int16", "int32", "int64", "char", "uint8",
                      "uint16", "uint32", "uint64"):
        return "0"
    if field_type in ("float32", "float64"):
        return "0."
    if field_type == "string":
        return "''"
    if field_type.endswith("]"):
        base, _is_array, length = parse_type(field_type)
        if base in ("byte", "uint8"):
            return f"chr(0)*{length}" if length is not None else "''"
        if length is None:
            return "[]"
        return "[" + ",".join(itertools.repeat(migration_default_value(base), length)) + "]"
    return f"self.get_new_class('{field_type}')()"


def constants_from_def(core_type: str, msg_def: str) -> Set[Tuple[str, Any, str]]:
    """``{(name, value, type)}`` of the constants of the core message of a full definition."""
    from minros.msgs.loader import MsgContext, load_msg_from_string

    core_text = msg_def.split("\n" + "=" * 80 + "\n")[0]
    package = core_type.split("/")[0]
    spec = load_msg_from_string(MsgContext.create_default(), core_text, core_type if "/" in core_type
                                else f"{package}/{core_type}")
    return {(c.name, c.val, c.type) for c in spec.constants}


def _default_for(field_type: str, rule: Any) -> Any:
    """The value ``migration_default_value`` writes, for a generated rule that runs."""
    if field_type in ("bool", "byte", "int8", "int16", "int32", "int64", "char", "uint8",
                      "uint16", "uint32", "uint64"):
        return 0
    if field_type in ("float32", "float64"):
        return 0.0
    if field_type == "string":
        return ""
    if field_type.endswith("]"):
        base, _is_array, length = parse_type(field_type)
        if base in ("byte", "uint8"):
            return bytes(length) if length is not None else b""
        if length is None:
            return []
        return [_default_for(base, rule) for _ in range(length)]
    return rule.get_new_class(field_type)()


# ---------------------------------------------------------------------------------------------
# rules

class MessageUpdateRule:
    """A migration from ``old_type`` (as ``old_full_text`` defines it) to ``new_type`` (as
    ``new_full_text``): subclasses set those, ``migrated_types`` (the ``(old, new)`` sub-types
    ``update`` migrates with ``self.migrate``/``self.migrate_array``), ``order`` within the
    type's chain, ``valid = True``, and write ``update(old_msg, new_msg)``."""

    old_type = ""
    old_full_text = ""
    new_type = ""
    new_full_text = ""
    migrated_types: List[Tuple[str, str]] = []
    order = -1
    valid = False

    class EmptyType(Exception):
        """The rule names no type on this side (a half rule)."""

    def __init__(self, migrator: MessageMigrator, location: str) -> None:
        self.migrator = migrator
        self.location = location
        self.rename_rule = self.old_type != self.new_type
        self.old_types, self.old_class, self.old_md5sum = self._classes(self.old_type,
                                                                        self.old_full_text)
        self.new_types, self.new_class, self.new_md5sum = self._classes(self.new_type,
                                                                        self.new_full_text)
        self.sub_rules_done = False
        self.sub_rules_valid = False
        self.sub_rules: List[MessageUpdateRule] = []

    def _classes(self, type_name: str, full_text: str) -> Tuple[Dict[str, Any], Any, str]:
        if not type_name:
            return {}, None, ""
        try:
            types = generate_dynamic(type_name, full_text)
            return types, types[type_name], types[type_name]._md5sum
        except Exception as exc:  # noqa: BLE001 - a bad definition in a rule: say which, go on
            _warn(f"ERROR: rule [{self.location}]: cannot build [{type_name}] from its "
                  f"definition: {exc}")
            return {}, None, ""

    def find_sub_paths(self) -> None:
        """Find the migration path of every sub-type in ``migrated_types``."""
        self.sub_rules_valid = True
        for old_name, new_name in self.migrated_types:
            try:
                old_sub = self.get_old_class(old_name)
            except KeyError:
                _warn(f"WARNING: Within rule [{self.location}], specified migrated type "
                      f"[{old_name}] not found in old message types")
                self.sub_rules_valid = False
                continue
            try:
                new_sub = self.get_new_class(new_name)
            except KeyError:
                _warn(f"WARNING: Within rule [{self.location}], specified migrated type "
                      f"[{new_name}] not found in new message types")
                self.sub_rules_valid = False
                continue
            # a rule naming its own pair (same md5 sums) must not recurse into itself
            if get_path_key(old_sub, new_sub) != get_path_key(self.old_class, self.new_class):
                self.sub_rules.extend(sn.rule for sn in self.migrator.find_path(old_sub, new_sub))
            if not all(r.valid for r in self.sub_rules):
                _warn(f"WARNING: Within rule [{self.location}] cannot migrate from subtype "
                      f"[{old_name}] to [{new_name}]..")
                self.sub_rules_valid = False
        self.sub_rules = self.migrator.filter_rules_unique(self.sub_rules)
        self.sub_rules_done = True

    @staticmethod
    def _lookup(types: Dict[str, Any], name: str, top_type: str) -> Any:
        for candidate in (name, "std_msgs/" + name, top_type.split("/")[0] + "/" + name):
            if candidate in types:
                return types[candidate]
        raise KeyError(name)

    def get_new_class(self, t: str) -> Any:
        """The class of sub-type ``t`` (``Sub``, ``pkg/Sub``) in the new definition."""
        return self._lookup(self.new_types, t, self.new_type)

    def get_old_class(self, t: str) -> Any:
        """The class of sub-type ``t`` in the old definition."""
        return self._lookup(self.old_types, t, self.old_type)

    def _check_listed(self, old_name: str, new_name: str) -> None:
        pair = (clean_name(old_name, self.old_type), clean_name(new_name, self.new_type))
        if pair not in [tuple(p) for p in self.migrated_types]:
            raise BagMigrationException(
                f"Rule [{self.location}] tried to perform a migration from old [{pair[0]}] to "
                f"new [{pair[1]}] not listed in migrated_types")

    def migrate(self, msg_from: Any, msg_to: Any) -> None:
        """Migrate the sub-message ``msg_from`` into ``msg_to`` (inside ``update``)."""
        self._check_listed(msg_from._type, msg_to._type)
        self.migrator.migrate(msg_from, msg_to)

    def migrate_array(self, msg_from_array: list, msg_to_array: list, msg_to_name: str) -> None:
        """Migrate every sub-message of ``msg_from_array`` into new ``msg_to_name`` messages
        in ``msg_to_array`` (emptied first)."""
        to_class = self.get_new_class(msg_to_name)
        del msg_to_array[:]
        if not msg_from_array:
            return
        self._check_listed(msg_from_array[0]._type, to_class._type)
        msg_to_array.extend(to_class() for _ in msg_from_array)
        self.migrator.migrate_array(msg_from_array, msg_to_array)

    def get_class_def(self) -> Optional[str]:
        """The Python source of a generated rule (None for a written one)."""
        return None

    def apply(self, old_msg: Any) -> Any:
        """The new message ``update`` makes of ``old_msg``."""
        if not self.valid:
            raise BagMigrationException("Attempted to apply an invalid rule")
        if not self.sub_rules_done:
            raise BagMigrationException("Attempted to apply a rule without building up its sub rules")
        if not self.sub_rules_valid:
            raise BagMigrationException("Attempted to apply a rule without valid sub-rules")
        if get_message_key(old_msg) != get_message_key(self.old_class):
            raise BagMigrationException(f"Attempted to apply rule to incorrect class "
                                        f"{get_message_key(old_msg)} {get_message_key(self.old_class)}.")
        new_msg = self.new_class()
        self.update(old_msg, new_msg)
        return new_msg

    def update(self, old_msg: Any, new_msg: Any) -> None:
        raise BagMigrationException("Tried to use rule without update overidden")


class RuleChain:
    """The rules of one old type: ``chain`` ordered by ``order``, then its ``rename``."""

    def __init__(self) -> None:
        self.chain: List[MessageUpdateRule] = []
        self.order_keys: Set[int] = set()
        self.rename: Optional[MessageUpdateRule] = None


class ScaffoldNode:
    """One step of a migration: ``rule`` takes ``old_class`` to ``new_class``; ``next`` is
    the step after it."""

    def __init__(self, old_class: Any, new_class: Any, rule: Optional[MessageUpdateRule]) -> None:
        self.old_class = old_class
        self.new_class = new_class
        self.rule = rule
        self.next: Optional[ScaffoldNode] = None


# -- rules the migrator generates: a field-by-field plan, and the source a person completes

def _literal(text: str) -> str:
    """``text`` as the triple-quoted literal rule files use, or repr() where it cannot be."""
    if '"""' in text or "\\" in text or text.endswith('"'):
        return repr("\n" + text + "\n")
    return '"""\n' + text + '\n"""'


def _rule_source(name: str, old_class: Any, new_class: Any, migrated: List[Tuple[str, str]],
                 valid: bool, body: List[str]) -> str:
    old_type = old_class._type if old_class is not None else ""
    new_type = new_class._type if new_class is not None else ""
    old_text = old_class._full_text.strip() if old_class is not None else ""
    new_text = new_class._full_text.strip() if new_class is not None else ""
    source = f"class {name}(MessageUpdateRule):\n"
    source += f'\told_type = "{old_type}"\n'
    source += f"\told_full_text = {_literal(old_text)}\n\n"
    source += f'\tnew_type = "{new_type}"\n'
    source += f"\tnew_full_text = {_literal(new_text)}\n"
    source += "\n\torder = 0\n"
    if migrated is None:
        source += "\tmigrated_types = []\n"
    else:
        source += "\tmigrated_types = [" + "".join(f'\n\t\t("{a}","{b}"),' for a, b in migrated) + "]\n"
    source += f"\n\tvalid = {valid}\n\n"
    source += "\tdef update(self, old_msg, new_msg):\n" + "".join(f"\t\t{line}\n" for line in body)
    return source


def _generated_rule(name: str, old_class: Any, new_class: Any, migrated: Any, valid: bool,
                    body: List[str], steps: List[Callable[[Any, Any, Any], None]]) -> type:
    source = _rule_source(name, old_class, new_class, migrated, valid, body)

    def update(self: Any, old_msg: Any, new_msg: Any) -> None:
        for step in steps:
            step(self, old_msg, new_msg)

    return type(name, (MessageUpdateRule,), {
        "old_type": old_class._type if old_class is not None else "",
        "old_full_text": old_class._full_text if old_class is not None else "",
        "new_type": new_class._type if new_class is not None else "",
        "new_full_text": new_class._full_text if new_class is not None else "",
        "order": 0, "migrated_types": list(migrated or []), "valid": valid, "update": update,
        "get_class_def": lambda self: source})


# ---------------------------------------------------------------------------------------------
# the migrator

RuleFactory = Callable[[Any, str], MessageUpdateRule]


class MessageMigrator:
    """The rules of the rule files given and (with ``plugins``) of the packages exporting
    them, arranged into the paths messages take to the installed definitions."""

    def __init__(self, input_rule_files: Sequence[str] = (), plugins: bool = True) -> None:
        self.rulechains: Dict[str, RuleChain] = collections.defaultdict(RuleChain)
        self.base_nodes: List[ScaffoldNode] = []
        self.extra_nodes: List[ScaffoldNode] = []
        self.first_type: Dict[str, ScaffoldNode] = {}
        self.rename_map: Dict[str, Set[str]] = {}
        self.found_paths: Dict[Any, List[ScaffoldNode]] = {}
        self.found_targets: Dict[Any, Any] = {}
        self.false_rule_loaded = False
        for namespace, location in self._rule_files(input_rule_files, plugins):
            for name, value in list(namespace.items()):
                if (isinstance(value, type) and issubclass(value, MessageUpdateRule)
                        and value is not MessageUpdateRule):
                    self.add_update_rule(value(self, f"{location}:{name}"))
        if self.false_rule_loaded:
            raise BagMigrationException("Cannot instantiate MessageMigrator with invalid rules")
        self._scaffold()
        self.class_dict: Dict[Any, Any] = {}
        for sn in self.base_nodes + self.extra_nodes:
            self.class_dict[get_message_key(sn.old_class)] = sn.old_class
            self.class_dict[get_message_key(sn.new_class)] = sn.new_class

    # -- loading

    @staticmethod
    def _run_rule_file(path: str) -> Dict[str, Any]:
        namespace: Dict[str, Any] = {"MessageUpdateRule": MessageUpdateRule}
        with open(path) as f:
            code = compile(f.read(), path, "exec")
        exec(code, namespace)  # noqa: S102 - rule files are Python by design (ROS's format)
        return namespace

    def _rule_files(self, files: Sequence[str], plugins: bool) -> Iterable[Tuple[Dict[str, Any], str]]:
        for path in files:
            try:
                yield self._run_rule_file(path), path
            except Exception as exc:  # noqa: BLE001 - a broken file is reported and skipped
                _warn(f"Cannot load rule file [{path}] in local package: {exc}")
        if not plugins:
            return
        from minros import packages

        rospack = packages.rospack()
        for dep, export in (("rosbagmigration", "rule_file"), ("rosbag", "migration_rule_file"),
                            ("rosbag_migration_rule", "rule_file")):
            try:
                exporters = rospack.get_depends_on(dep, implicit=False)
            except Exception:  # noqa: BLE001 - the package is not there: nothing exports to it
                exporters = []
            for package in exporters:
                try:
                    rules = rospack.get_manifest(package).get_export(dep, export)
                    package_dir = rospack.get_path(package)
                except Exception:  # noqa: BLE001 - an unreadable manifest exports nothing
                    continue
                for rule in rules:
                    path = os.path.join(package_dir, rule)
                    if not os.path.isfile(path):
                        continue  # minros bundles definitions, not old versions' rule files
                    if dep == "rosbagmigration":
                        _warn(f"WARNING: The package: [{package}] is using a deprecated "
                              f"rosbagmigration export.\n    The export in the manifest should "
                              f'be changed to:\n    <rosbag migration_rule_file="{rule}"/>\n')
                    try:
                        yield self._run_rule_file(path), rule
                    except Exception as exc:  # noqa: BLE001
                        _warn(f"Cannot load rule file [{rule}] in package [{package}]: {exc}")

    def add_update_rule(self, r: MessageUpdateRule) -> None:
        """Put ``r`` in its type's chain (a rename rule last), refusing conflicts."""
        if not r.valid:
            _warn(f"ERROR: Update rule [{r.location}] has valid set to False.")
            self.false_rule_loaded = True
            return
        chain = self.rulechains[r.old_type]
        if r.rename_rule:
            if chain.rename is not None:
                _warn(f"WARNING: Update rules [{chain.rename.location}] and [{r.location}] both "
                      f"attempting to rename type [{r.old_type}]. Ignoring [{r.location}]")
                return
            cycle: List[MessageUpdateRule] = []
            step: Optional[MessageUpdateRule] = r
            while step is not None:
                cycle.append(step)
                if step.new_type == r.old_type:
                    _warn(f"WARNING: Update rules {[x.location for x in cycle]} introduce a "
                          f"renaming cycle. Ignoring [{r.location}]")
                    return
                step = self.rulechains[step.new_type].rename if step.new_type in self.rulechains else None
            if chain.chain and r.order <= chain.chain[-1].order:
                _warn(f"WARNING: Update rule [{r.location}] which performs rename does not have "
                      "largest order number. Ignoring")
                return
            chain.rename = r
            return
        if r.order in chain.order_keys:
            other = next(x for x in chain.chain if x.order == r.order)
            _warn(f"WARNING: Update rules [{other.location}] and [{r.location}] for type "
                  f"[{r.old_type}] have the same order number. Ignoring [{r.location}]")
            return
        if chain.rename is not None and r.order >= chain.rename.order:
            _warn(f"WARNING: Update rule [{r.location}] has order number larger than rename rule "
                  f"[{chain.rename.location}]. Ignoring")
            return
        chain.order_keys.add(r.order)
        chain.chain.append(r)
        chain.chain.sort(key=lambda x: x.order)

    # -- the scaffold: each type's chain, bridged to the installed definitions

    def _link(self, prev: Optional[ScaffoldNode], sn: ScaffoldNode) -> None:
        if prev is None:
            return
        if get_message_key(prev.new_class) == get_message_key(sn.old_class):
            prev.next = sn
        else:  # a gap between two rules: a rule to be generated bridges it
            bridge = ScaffoldNode(prev.new_class, sn.old_class, None)
            self.base_nodes.append(bridge)
            prev.next = bridge
            bridge.next = sn

    def _generate(self, old_class: Any, new_class: Any) -> MessageUpdateRule:
        factory = self.make_update_rule(old_class, new_class)
        return factory(self, "GENERATED." + factory.__name__)

    def _scaffold(self) -> None:
        terminals: List[ScaffoldNode] = []
        for type_name, chain in list(self.rulechains.items()):
            renames = {type_name}
            step = chain.rename
            while step is not None:
                renames.add(step.new_type)
                step = self.rulechains[step.new_type].rename if step.new_type in self.rulechains else None
            self.rename_map[type_name] = renames
            prev: Optional[ScaffoldNode] = None
            for r in chain.chain + ([chain.rename] if chain.rename is not None else []):
                sn = ScaffoldNode(r.old_class, r.new_class, r)
                self.base_nodes.append(sn)
                self.first_type.setdefault(type_name, sn)
                self._link(prev, sn)
                prev = sn
            if prev is not None:
                terminals.append(prev)
        for sn in terminals:
            self._terminate(sn)
        for sn in self.base_nodes:
            if sn.rule is None:
                sn.rule = self._generate(sn.old_class, sn.new_class)
        for sn in self.base_nodes:
            sn.rule.find_sub_paths()

    def _terminate(self, sn: ScaffoldNode) -> None:
        """Continue a chain's last node to the installed class (or a placeholder rule)."""
        renamed = sn.old_class._type != sn.new_class._type
        system = _system_class(sn.new_class._type)
        if system is not None:
            r = self._generate(sn.new_class, system)
            if r.valid:
                sn.next = ScaffoldNode(sn.new_class, system, r)
                self.base_nodes.append(sn.next)
        if renamed:
            following = self.scaffold_range(sn.new_class._type, sn.new_class._type)
            if not following and system is not None:
                sn.next = ScaffoldNode(sn.new_class, system, None)
                self.base_nodes.append(sn.next)
                return
            key = get_message_key(sn.new_class)
            for candidate in reversed(following):
                if get_message_key(candidate.old_class) == key:
                    sn.next = candidate
                    break
            if sn.next is None:  # a generated bridge as late in the following chain as can be
                for candidate in reversed(following):
                    r = self._generate(sn.new_class, candidate.old_class)
                    if r.valid:
                        sn.next = ScaffoldNode(sn.new_class, candidate.old_class, r)
                        self.base_nodes.append(sn.next)
                        break
        if sn.next is None:
            factory = (self.make_update_rule(sn.new_class, system) if system is not None
                       else self.make_old_half_rule(sn.new_class))
            sn.next = ScaffoldNode(sn.new_class, None, factory(self, "GENERATED." + factory.__name__))
            self.base_nodes.append(sn.next)

    # -- queries

    def lookup_type(self, key: Any) -> Any:
        return self.class_dict.get(key)

    def all_rules_valid(self) -> bool:
        return all(sn.rule.valid for sn in self.base_nodes + self.extra_nodes)

    def get_invalid_rules(self) -> List[MessageUpdateRule]:
        return self.filter_rules_unique([sn.rule for sn in self.base_nodes + self.extra_nodes
                                         if not sn.rule.valid])

    def filter_rules_unique(self, rules: Iterable[MessageUpdateRule]) -> List[MessageUpdateRule]:
        """``rules`` with one rule per (old, new) pair of definitions."""
        seen: Set[Any] = set()
        unique = []
        for r in rules:
            key = get_path_key(r.old_class, r.new_class)
            if key not in seen:
                seen.add(key)
                unique.append(r)
        return unique

    def expand_rules(self, rules: Iterable[MessageUpdateRule]) -> List[MessageUpdateRule]:
        """``rules`` and, after each, the rules of its sub-messages."""
        expanded: List[MessageUpdateRule] = []
        for r in self.filter_rules_unique(rules):
            expanded.append(r)
            expanded.extend(self.expand_rules(r.sub_rules))
        return self.filter_rules_unique(expanded)

    def scaffold_range(self, old_type: str, new_type: str) -> List[ScaffoldNode]:
        """The scaffold nodes from ``old_type``'s first rule until the chain has reached
        ``new_type`` and left it again (or ends)."""
        first = self.first_type.get(old_type)
        if first is None:
            return []
        nodes = [first]
        reached = False
        sn = first
        while sn.next is not None and sn.next.new_class is not None:
            sn = sn.next
            if sn is not first:
                nodes.append(sn)
            if sn.new_class._type == new_type:
                reached = True
            if reached and sn.new_class._type != new_type:
                break
        return nodes

    def find_target(self, old_class: Any) -> Any:
        """The installed class messages of ``old_class`` migrate to (following renames), or
        None when the type is not installed and no rule renames it to one that is."""
        key = get_message_key(old_class)
        if key in self.found_targets:
            return self.found_targets[key]
        target = _system_class(old_class._type)
        if target is None and old_class._type in self.first_type:
            sn = self.first_type[old_class._type]
            while sn.next is not None:
                sn = sn.next
            if sn.new_class is not None:
                target = _system_class(sn.new_class._type)
        self.found_targets[key] = target
        return target

    def _rule_if_valid(self, old_class: Any, new_class: Any) -> Optional[MessageUpdateRule]:
        r = self._generate(old_class, new_class)
        if not r.valid:
            return None
        r.find_sub_paths()
        return r if r.sub_rules_valid else None

    def find_path(self, old_class: Any, new_class: Any) -> List[ScaffoldNode]:
        """The steps from ``old_class`` to ``new_class`` (empty when the definitions are the
        same); steps whose rule is not valid mark what a person must write."""
        key = get_path_key(old_class, new_class)
        if key in self.found_paths:
            return self.found_paths[key]
        if new_class is None:
            path = self._path_to_nowhere(old_class)
        elif (old_class._type == new_class._type
              and old_class._full_text.strip() == new_class._full_text.strip()):
            path = []
        else:
            path = self._path_between(old_class, new_class)
        self.found_paths[key] = path
        return path

    def _path_to_nowhere(self, old_class: Any) -> List[ScaffoldNode]:
        """A type that moved without a rename rule: as far as the rules go, then a half rule."""
        nodes = self.scaffold_range(old_class._type, "")
        start = self._start(nodes, old_class, direct_to=None)
        nodes = start if start is not None else nodes
        last = nodes[-1].new_class if nodes else old_class
        factory = self.make_old_half_rule(last)
        sn = ScaffoldNode(last, None, factory(self, "GENERATED." + factory.__name__))
        self.extra_nodes.append(sn)
        return nodes + [sn]

    def _start(self, nodes: List[ScaffoldNode], old_class: Any,
               direct_to: Any) -> Optional[List[ScaffoldNode]]:
        """``nodes`` from where ``old_class`` enters them (a node of the same definition, else
        a valid generated rule to the latest node of its type), or None."""
        key = get_message_key(old_class)
        for i in reversed(range(len(nodes))):
            if nodes[i].old_class._type == old_class._type and get_message_key(nodes[i].old_class) == key:
                return nodes[i:]
        if direct_to is not None:
            r = self._rule_if_valid(old_class, direct_to)
            if r is not None:
                sn = ScaffoldNode(old_class, direct_to, r)
                self.extra_nodes.append(sn)
                return [sn]
        for i in reversed(range(len(nodes))):
            if nodes[i].old_class._type != old_class._type:
                continue
            r = self._rule_if_valid(old_class, nodes[i].old_class)
            if r is not None:
                sn = ScaffoldNode(old_class, nodes[i].old_class, r)
                self.extra_nodes.append(sn)
                return [sn] + nodes[i:]
        return None

    def _path_between(self, old_class: Any, new_class: Any) -> List[ScaffoldNode]:
        nodes = self.scaffold_range(old_class._type, new_class._type)
        if not nodes:  # no rules for the type: one generated rule, valid or for a person
            r = self._generate(old_class, new_class)
            r.find_sub_paths()
            sn = ScaffoldNode(old_class, new_class, r)
            self.extra_nodes.append(sn)
            return [sn]
        # where the scaffold reaches new_class: the same definition, else a valid rule to it
        stop = None
        key = get_message_key(new_class)
        for i in reversed(range(len(nodes))):
            if nodes[i].new_class._type != new_class._type:
                break
            if get_message_key(nodes[i].new_class) == key:
                stop = nodes[:i + 1]
                break
        if stop is None:
            for i in reversed(range(len(nodes))):
                if nodes[i].new_class._type != new_class._type:
                    break
                r = self._rule_if_valid(nodes[i].new_class, new_class)
                if r is not None:
                    sn = ScaffoldNode(nodes[i].new_class, new_class, r)
                    self.extra_nodes.append(sn)
                    stop = nodes[:i + 1] + [sn]
                    break
        if stop is None:  # a rule for a person to write, from the end of the scaffold
            r = self._generate(nodes[-1].new_class, new_class)
            r.find_sub_paths()
            sn = ScaffoldNode(nodes[-1].new_class, new_class, r)
            self.extra_nodes.append(sn)
            stop = nodes + [sn]
        start = self._start(stop, old_class, direct_to=new_class)
        if start is not None:
            return start
        r = self._generate(old_class, stop[0].old_class)
        r.find_sub_paths()
        sn = ScaffoldNode(old_class, stop[0].old_class, r)
        self.extra_nodes.append(sn)
        return [sn] + stop

    # -- migrating

    def _run_path(self, path: List[ScaffoldNode], data: bytes) -> bytes:
        msg = path[0].old_class()
        msg.deserialize(data)
        for sn in path:
            msg = sn.rule.apply(msg)
        out = io.BytesIO()
        msg.serialize(out)
        return out.getvalue()

    def migrate_raw(self, msg_from: tuple, msg_to: tuple) -> tuple:
        """A raw bag message ``(type, bytes, md5sum, position, class)`` migrated to the
        definition of ``msg_to`` (of the same shape; its bytes are ignored)."""
        path = self.find_path(msg_from[4], msg_to[4])
        if not all(sn.rule.valid for sn in path):
            raise BagMigrationException(f"Migrate called, but no valid migration path from "
                                        f"[{msg_from[0]}] to [{msg_to[0]}]")
        if not path or msg_from[2] == msg_to[2]:
            return (msg_to[0], msg_from[1], msg_to[2], msg_to[3], msg_to[4])
        return (msg_to[0], self._run_path(path, msg_from[1]), msg_to[2], msg_to[3], msg_to[4])

    def migrate(self, msg_from: Any, msg_to: Any) -> None:
        """Fill ``msg_to`` with ``msg_from`` migrated to its definition."""
        path = self.find_path(type(msg_from), type(msg_to))
        if not all(sn.rule.valid for sn in path):
            raise BagMigrationException(f"Migrate called, but no valid migration path from "
                                        f"[{msg_from._type}] to [{msg_to._type}]")
        out = io.BytesIO()
        msg_from.serialize(out)
        data = out.getvalue()
        if path and msg_from._md5sum != msg_to._md5sum:
            data = self._run_path(path, data)
        msg_to.deserialize(data)

    def migrate_array(self, msg_from_array: list, msg_to_array: list) -> None:
        """Migrate each message of ``msg_from_array`` into the one at its index in
        ``msg_to_array``."""
        if len(msg_from_array) != len(msg_to_array):
            raise BagMigrationException("Migrate array called on on arrays of unequal length.")
        for msg_from, msg_to in zip(msg_from_array, msg_to_array):
            self.migrate(msg_from, msg_to)

    # -- generated rules

    def make_update_rule(self, old_class: Any, new_class: Any) -> RuleFactory:
        """A rule class from ``old_class`` to ``new_class``: fields copied by name, sub-messages
        migrated; valid only if every field is matched and no constant changed (else its
        source marks, for a person, what is missing)."""
        name = f"update_{old_class._type.replace('/', '_')}_{old_class._md5sum}"
        valid = True
        body: List[str] = []
        steps: List[Callable[[Any, Any, Any], None]] = []
        migrated: List[Tuple[str, str]] = []
        old_consts = constants_from_def(old_class._type, old_class._full_text)
        new_consts = constants_from_def(new_class._type, new_class._full_text)
        if not new_consts >= old_consts:
            valid = False
            body.extend(f"#Constant '{c[0]}' has changed" for c in old_consts - new_consts)
        unmatched = list(old_class.__slots__)
        for field, field_type in zip(new_class.__slots__, new_class._slot_types):
            problem = None
            new_base, new_is_array, new_len = parse_type(field_type)
            if field not in old_class.__slots__:
                problem = "No matching field name in old message"
            else:
                unmatched.remove(field)
                old_type = old_class._slot_types[old_class.__slots__.index(field)]
                old_base, old_is_array, old_len = parse_type(old_type)
                if new_is_array != old_is_array:
                    problem = "Could not match array with nonarray"
                elif new_len != old_len:
                    if old_len is None:
                        problem = f"Converted from variable length array to fixed array of length {new_len}"
                    elif new_len is None:
                        problem = f"Converted from fixed array of length {old_len} to variable length"
                    else:
                        problem = f"Fixed length array converted from {old_len} to {new_len}"
                elif is_builtin(new_base):
                    if new_base != old_base:
                        problem = "Primitive type changed"
                    else:
                        body.append(f"new_msg.{field} = old_msg.{field}")
                        steps.append(lambda self, o, n, f=field: setattr(n, f, getattr(o, f)))
                else:
                    old_short, new_short = clean_name(old_base, old_class._type), clean_name(new_base, new_class._type)
                    old_q = qualified_name(old_base, old_class._type)
                    new_q = qualified_name(new_base, new_class._type)
                    if old_q == new_q or new_q in self.rename_map.get(old_q, ()):
                        if (old_short, new_short) not in migrated:
                            migrated.append((old_short, new_short))
                        if not new_is_array:
                            body.append(f"self.migrate(old_msg.{field}, new_msg.{field})")
                            steps.append(lambda self, o, n, f=field: self.migrate(getattr(o, f), getattr(n, f)))
                        else:
                            body.append(f'self.migrate_array(old_msg.{field}, new_msg.{field}, "{new_base}")')
                            steps.append(lambda self, o, n, f=field, b=new_base:
                                         self.migrate_array(getattr(o, f), getattr(n, f), b))
                    else:
                        problem = f"No migration path between [{old_short}] and [{new_short}]"
            if problem is not None:
                valid = False
                body.append(f"#{problem}")
                body.append(f"new_msg.{field} = {migration_default_value(field_type)}")
                steps.append(lambda self, o, n, f=field, t=field_type: setattr(n, f, _default_for(t, self)))
        if unmatched:
            valid = False
            body.extend(f"#No field to match field {f} from old message" for f in unmatched)
        return _generated_rule(name, old_class, new_class, migrated, valid, body or ["pass"], steps)

    def make_old_half_rule(self, old_class: Any) -> RuleFactory:
        """A placeholder rule from ``old_class`` to a type still to be named (never valid)."""
        name = f"update__{old_class._type.replace('/', '_')}__{old_class._md5sum}"
        return _generated_rule(name, old_class, None, None, False, ["pass"], [])

    def make_new_half_rule(self, new_class: Any) -> RuleFactory:
        """A placeholder rule to ``new_class`` from a type still to be named (never valid)."""
        name = f"update_to_{new_class._type.replace('/', '_')}_{new_class._md5sum}"
        return _generated_rule(name, None, new_class, None, False, ["pass"], [])


# ---------------------------------------------------------------------------------------------
# bags

def _check_classes(migrator: MessageMigrator, classes: Iterable[Any]) -> List[Tuple[list, list]]:
    migrations = []
    seen: Set[Any] = set()
    for cls in classes:
        key = get_message_key(cls)
        if key in seen:
            continue
        seen.add(key)
        path = migrator.find_path(cls, migrator.find_target(cls))
        if path:
            missing = [r for r in migrator.expand_rules([sn.rule for sn in path]) if not r.valid]
            migrations.append((path, missing))
    return migrations


def _bag_classes(path: str) -> List[Any]:
    """The class of each definition in a bag (the installed class where the md5 sums agree),
    in the order their first messages come."""
    classes: Dict[Any, Any] = {}
    with Bag(path, "r") as bag:
        for _topic, msg, _t in bag.read_messages(raw=True):
            classes.setdefault(get_message_key(msg[4]), msg[4])
    return list(classes.values())


def checkbag(migrator: MessageMigrator, inbag: str) -> List[Tuple[list, list]]:
    """For each type in the bag that needs migrating: ``(path, rules missing from it)``."""
    return _check_classes(migrator, _bag_classes(inbag))


def checkmessages(migrator: MessageMigrator, messages: Iterable[Any]) -> List[Tuple[list, list]]:
    """checkbag for message classes (or instances)."""
    return _check_classes(migrator, messages)


def _migrated_header(header: dict, new_class: Any) -> dict:
    header = dict(header)
    header["type"] = new_class._type
    header["md5sum"] = new_class._md5sum
    header["message_definition"] = new_class._full_text
    return header


def _rewrite(migrator: MessageMigrator, inbag: str, outbag: str) -> None:
    with Bag(inbag, "r") as bag:
        options = bag.options
        with Bag(outbag, "w", options=options) as out:
            for topic, msg, t, header in bag.read_messages(raw=True, return_connection_header=True):
                target = migrator.find_target(msg[4])
                if target is None:
                    out.write(topic, msg, t, raw=True, connection_header=header)
                    continue
                new = migrator.migrate_raw(msg, (target._type, None, target._md5sum, None, target))
                out.write(topic, new, t, raw=True, connection_header=_migrated_header(header, target))


def fixbag(migrator: MessageMigrator, inbag: str, outbag: str) -> bool:
    """Write ``outbag`` with every message migrated; False (nothing written) when a rule is
    missing."""
    if any(missing for _path, missing in checkbag(migrator, inbag)):
        return False
    _rewrite(migrator, inbag, outbag)
    return True


def fixbag2(migrator: MessageMigrator, inbag: str, outbag: str,
            force: bool = False) -> List[Tuple[list, list]]:
    """Write ``outbag`` with every message migrated; the migrations that cannot be done (and
    nothing written), unless ``force`` writes the bag anyway."""
    blocked = [m for m in checkbag(migrator, inbag) if m[1]]
    if not blocked or force:
        _rewrite(migrator, inbag, outbag)
    return [] if force else blocked
