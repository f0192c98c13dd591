"""What a tree can use of the robot, read from its nodes: the speaker, the face LEDs, the
joints. Two trees that can want one resource at the same priority take turns by who asks
first, which a therapist rarely means: :func:`collisions` names them at load time."""

from __future__ import annotations

from dataclasses import dataclass

from engine.loader.tree_definition import TreeDefinition
from engine.nodes.spec import ANY_JOINT


def tree_resources(definition: TreeDefinition) -> set[str]:
    """The resources the nodes of ``definition`` use, as each node type declares them
    (:attr:`~engine.nodes.spec.NodeType.uses`; a plugin's nodes included)."""
    used: set[str] = set()
    for node in definition.root.walk():
        used |= node.type.resources(node.args)
    return used


@dataclass(frozen=True)
class Collision:
    """Two trees of one priority that can want the same resources."""

    first: TreeDefinition
    second: TreeDefinition
    resources: tuple[str, ...]

    def describe(self) -> str:
        shared = " and ".join(
            "any of the joints" if resource == ANY_JOINT else f"the {resource}"
            for resource in self.resources
        )
        return (
            f"trees {self.first.name!r} and {self.second.name!r} both use {shared} at "
            f"priority {self.first.priority}: when both want it, the first to ask has it "
            f"(give one of them a higher 'priority:')"
        )


def collisions(definitions: list[TreeDefinition]) -> list[Collision]:
    """Each pair of trees of equal priority that share a resource, in file order."""
    used = [(definition, tree_resources(definition)) for definition in definitions]
    found: list[Collision] = []
    for index, (first, first_uses) in enumerate(used):
        for second, second_uses in used[index + 1 :]:
            if first.priority != second.priority:
                continue
            shared = _shared(first_uses, second_uses)
            if shared:
                found.append(Collision(first, second, tuple(sorted(shared))))
    return found


def _shared(first: set[str], second: set[str]) -> set[str]:
    shared = first & second
    joints = {r for r in first | second if r.endswith(" joint") and r != ANY_JOINT}
    if ANY_JOINT in first:
        shared |= joints & second
    if ANY_JOINT in second:
        shared |= joints & first
    return shared
