"""What the files show that no drafted part covers, asked as ``DECIDE`` questions (issue 30).

Why: a mark on a drafted item asks about that item; an item the draft leaves out (a hand not
drafted at all, two arms the tree did not recognise) had nothing near it to ask, so the user was
told nothing. After every part is drafted, this module looks at what is left:

* moving joints (not mimics, not wheels or casters, not the base's own joints) that belong to no
  chain, torso, neck or manipulator, one question per subtree they form: a serial run of three
  or more is "an arm? a leg? a head?", several branches hanging together are "a hand?", a short
  run is "a tool? a passive joint?", a run carrying drafted chains "a torso?";
* frames that look like cameras and are no drafted camera's device: a Gazebo sensor of an
  image kind the draft did not take, a link named as a camera (with or without a shape: on
  the tune half and example-robot-data, shaped ones all sit beside a drafted camera) or drawn
  with a mesh named as one, or a bare frame with a generic name turned as optical frames are
  (x level, y down: a rear camera, a depth camera tilted down; not at a limb's end or on a
  finger, where tool frames and tips are); one question per device (frames fixed to one link
  within 10 cm): ``unassigned_cameras``.

A drafted neck of more than three joints, or torso of more than four, is asked about too (an
arm carrying a camera taken for a neck leaves no joint uncovered), and so is a drafted leg (or
arm) of more joints than another of its kind (an arm mounted on a leg's calf: its joints past
the shortest leg's count). A wheel-shaped joint counts
as covered (the drive's) only when nothing but free turning joints moves below it (a ball
caster's axes): a leg's hip modelled as a continuous joint with a round motor is asked about
like any other joint.

A robot whose every moving joint is covered gets no question. Each question carries its subject
(the joints and links it names) for the corpus measure, which counts a missed item as asked
when a question names it (``tools/draft_score.py``); the spec holds only the comment.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from robotspec.errors import RobotSpecError
from robotspec.model.entities import Connection, ConnectionType
from robotspec.spec.draft.model import DraftQuestion
from robotspec.spec.draft.open_ends import open_end_questions
from robotspec.spec.draft.tree import words
from robotspec.spec.draft.unassigned_cameras import SENSORS, camera_questions

if TYPE_CHECKING:
    from robotspec.spec.draft.build import Drafter
    from robotspec.spec.draft.model import Draft, DraftChain

__all__ = ["CHAINS", "MANIPULATORS", "SENSORS", "asked", "find_questions"]

#: The spec sections a question is written in (where the part it asks about would go).
CHAINS, MANIPULATORS = "chains", "manipulators"
#: A run of at least this many joints is a limb's (an arm, a leg, a head); fewer, a tool's.
_LIMB_JOINTS = 3
#: The most joints a drafted neck and torso turn on before they are asked about (a head's pan,
#: tilt and roll; a mobile manipulator's lift and waist, four on Galaxea's R1).
_LONGEST = {"neck": 3, "torso": 4}
#: Joints named at most this many in a question; longer lists are written first .. last.
_SHOWN = 4
#: Words naming a rotor's joint (a drone's): it moves the robot, it is no part.
_ROTORS = frozenset({"rotor", "rotors", "propeller", "prop"})


def _covered(d: Drafter) -> set[int]:
    """Indices of the connections some drafted part (or the drive) accounts for."""
    world, draft = d.world, d.draft
    names: set[str] = set()
    for part in [*draft.chains, draft.torso, draft.neck]:
        if part is not None:
            names |= part.joints
    if draft.drive is not None:
        names |= {j for j in (draft.drive.joint, *(draft.drive.joints or ())) if j}
    base = d.own_base
    if base is not None:
        names |= set(base.joints or ()) | ({base.planar} if base.planar else set())
    out = {world.get_connection_by_name(n).index for n in names if world.has_connection(n)}
    # A wheel carries nothing that moves but free turning joints (a ball caster's axes): a
    # wheel-shaped joint with a limited joint below it (a leg's hip modelled continuous, with
    # a round motor) is asked about like any other joint.
    out |= {c.index for c in (*d.wheels, *d.wheel_shaped) if _rolls_freely(d, c)}
    for m in draft.manipulators:
        if world.has_body(m.root):
            for b in world.subtree(world.get_body_by_name(m.root)):
                up = world.parent_connection(b)
                if up is not None and b.name != m.root:
                    out.add(up.index)
    return out


def _rolls_freely(d: Drafter, c: Connection) -> bool:
    """Whether only continuous joints move below ``c`` (a wheel, a ball caster's axes)."""
    world = d.world
    return all(
        k.type is ConnectionType.CONTINUOUS or k.is_fixed or k.is_mimic
        for b in world.subtree(world.bodies[c.child])
        if (k := world.parent_connection(b)) is not None and b.index != c.child
    )


def _caster(d: Drafter, c: Connection) -> bool:
    """A caster's swivel or wheel: it follows the base, nobody commands it."""
    world = d.world
    named = words(c.name) | words(world.bodies[c.child].name)
    if named & {"caster", "castor", "swivel"}:
        return True
    # A swivel: a vertical turning joint whose child carries a wheel's continuous joint.
    kids = [world.parent_connection(k) for k in world.child_bodies(world.bodies[c.child])]
    return (
        any(
            k is not None and "wheel" in words(k.name) | words(world.bodies[k.child].name)
            for k in kids
        )
        and abs(float(d.tree.axis_in_root(c)[2])) > 0.9
    )


def _span(names: list[str]) -> str:
    if len(names) <= _SHOWN:
        return ", ".join(names)
    return f"{names[0]} .. {names[-1]} ({len(names)} joints)"


def _joint_questions(d: Drafter) -> list[DraftQuestion]:
    """One question per subtree of moving joints no drafted part covers."""
    world, tree = d.world, d.tree
    covered = _covered(d)
    loose: list[Connection] = []
    for c in world.connections:
        if not (c.is_active and c.is_1dof) or c.index in covered or c.child not in tree.inside:
            continue  # a floating or planar joint moves the whole robot: the drive's
        if c.child == tree.root.index or _caster(d, c) or _ROTORS & words(c.name):
            continue  # a caster follows the base; a rotor lifts it (the drive's)
        loose.append(c)
    if not loose:
        return []
    loose_ids = {c.index for c in loose}
    # Each loose joint's top: the highest loose joint above it with only fixed, mimic or loose
    # joints between them (a covered joint ends the walk).
    groups: dict[int, list[Connection]] = {}
    for c in loose:
        highest = c
        body = world.bodies[c.parent]
        while (up := world.parent_connection(body)) is not None and body is not tree.root:
            if up.is_active and up.index not in loose_ids:
                break
            if up.index in loose_ids:
                highest = up
            body = world.bodies[up.parent]
        groups.setdefault(highest.index, []).append(c)
    # Short runs hanging from one link are one device's (a hand's fingers, a gripper's jaws).
    by_parent: dict[int, list[list[Connection]]] = {}
    out: list[DraftQuestion] = []
    for top_index, joints in groups.items():
        if len(joints) >= _LIMB_JOINTS:
            out.append(_subtree_question(d, [joints]))
        else:
            by_parent.setdefault(world.connections[top_index].parent, []).append(joints)
    for runs in by_parent.values():
        out.append(_subtree_question(d, runs))
    out.sort(key=lambda q: min(world.get_connection_by_name(j).index for j in q.joints))
    return out


def _subtree_question(d: Drafter, runs: list[list[Connection]]) -> DraftQuestion:
    """The question about one or more loose runs hanging together."""
    world = d.world
    joints = sorted((c for run in runs for c in run), key=lambda c: c.index)
    links: set[str] = set()
    for c in joints:
        stack = [world.bodies[c.child]]
        while stack:  # the joint's link and what is fixed on it
            b = stack.pop()
            links.add(b.name)
            for k in world.child_bodies(b):
                kc = world.parent_connection(k)
                if kc is not None and (kc.is_fixed or kc.is_mimic):
                    stack.append(k)
    top = world.bodies[joints[0].parent].name
    deepest = max((world.bodies[c.child] for c in joints), key=world.depth)
    leaves = sum(1 for c in joints if not _has_loose_below(world, c, joints))
    trunk = _trunk(world, joints) if len(runs) == 1 else 0
    names = [c.name for c in joints]
    below = _carries_chains(d, joints)
    if below and len(runs) == 1 and leaves == 1:
        section, guess = CHAINS, f"a torso (it carries {below})? a passive joint?"
    elif trunk >= _LIMB_JOINTS:
        section, guess = CHAINS, "an arm? a leg? a head?"
        if leaves >= 2:
            guess += f" with {leaves} branches at its end: a hand or a gripper?"
    elif leaves >= 3:
        section, guess = MANIPULATORS, f"a hand ({leaves} branches)?"
    elif len(joints) >= _LIMB_JOINTS and leaves == 1:
        section, guess = CHAINS, "an arm? a leg? a head?"
    elif len(joints) == 2 and leaves == 1:
        section, guess = CHAINS, "a short arm? a head? a tool? a passive joint?"
    elif len(joints) == 1:
        section, guess = MANIPULATORS, "a tool? a sensor's mount? a passive joint?"
    else:
        section, guess = MANIPULATORS, "a gripper? a tool? passive joints?"
    text = f"joints {_span(names)} ({top} -> {deepest.name}) belong to no part: {guess}"
    return DraftQuestion(section, text, frozenset(names), frozenset(links))


def _carries_chains(d: Drafter, joints: list[Connection]) -> str:
    """The drafted chains below the last of ``joints`` (a torso's), named; "" when none."""
    world = d.world
    last = world.bodies[joints[-1].child]
    names = [
        c.name
        for c in d.draft.chains
        if world.has_body(c.root) and world.is_ancestor(last, world.get_body_by_name(c.root))
    ]
    return ", ".join(names[:_SHOWN])


def _trunk(world: object, joints: list[Connection]) -> int:
    """How many of ``joints`` (one subtree, top first) run serially before the first branching."""
    from robotspec.model.world import World

    assert isinstance(world, World)
    n, c = 0, joints[0]
    while True:
        n += 1
        below = [
            o
            for o in joints
            if o is not c and world.is_ancestor(world.bodies[c.child], world.bodies[o.child])
        ]
        if not below:
            return n
        nxt = min(below, key=lambda o: world.depth(world.bodies[o.child]))
        if any(
            not world.is_ancestor(world.bodies[nxt.child], world.bodies[o.child]) for o in below
        ):
            return n  # two branches below c: the trunk ends here
        c = nxt


def _has_loose_below(world: object, c: Connection, joints: list[Connection]) -> bool:
    from robotspec.model.world import World

    assert isinstance(world, World)
    child = world.bodies[c.child]
    return any(o is not c and world.is_ancestor(child, world.bodies[o.child]) for o in joints)


def _long_part_questions(d: Drafter) -> list[DraftQuestion]:
    """A drafted neck or torso of more joints than a head or a waist turns on: what is it?

    Why: a limb the draft took for a neck (an arm carrying a camera) or a torso leaves its
    joints covered, and nothing would ask about the arm or leg they make.
    """
    out = []
    for part in (d.draft.neck, d.draft.torso):
        if part is None or len(part.joints) <= _LONGEST.get(part.role, 4):
            continue
        names = sorted(part.joints, key=lambda j: d.world.get_connection_by_name(j).index)
        kind = "an arm carrying a camera" if part.role == "neck" else "an arm? a leg"
        text = (
            f"the {part.role} moves {len(names)} joints ({_span(names)}), more than a "
            f"{'head' if part.role == 'neck' else 'waist'} turns on: {kind}?"
        )
        out.append(DraftQuestion(CHAINS, text, frozenset(names), frozenset()))
    return out


def _uneven_limb_questions(d: Drafter) -> list[DraftQuestion]:
    """A drafted leg (or arm) of more joints than the others of its kind: what do they carry?

    Why: a robot's legs are alike, and so are its two arms; a leg of six joints beside legs of
    three runs on past its foot into another part (an arm mounted on a leg), an arm longer
    than its mirror into a hand's or a tool's joint. The drafted limb covers those joints, so
    nothing else would ask about the part they make. Which end holds the joint more the tree
    does not say (a waist joint inside an arm's run is one too): the question names the joints
    past the shortest limb's count, the links they carry, and asks about both ends.
    """
    world = d.world
    out = []
    for role in ("leg", "arm"):
        runs = {c.name: _moving_run(d, c) for c in d.draft.chains if c.role == role}
        runs = {name: run for name, run in runs.items() if run}
        if len(runs) < 2:
            continue
        least = min(len(run) for run in runs.values())
        for name, run in runs.items():
            extra = [j for j in run[least:] if j.is_active]
            if not extra:
                continue
            names = [j.name for j in extra]
            every = frozenset(j.name for j in run if j.is_active)
            links = frozenset(b.name for b in world.subtree(world.bodies[extra[0].child]))
            text = (
                f"{name} moves {len(run)} joints, another {role} {least}: a part more at its "
                f"end ({_span(names)}: an arm on the {role}? a hand's joint?) or at its start "
                "(a torso's joint)?"
            )
            out.append(DraftQuestion(CHAINS, text, every, links))
    return out


def _moving_run(d: Drafter, c: DraftChain) -> list[Connection]:
    """The moving joints from a drafted chain's root to its tip, root first, mimics included.

    Why mimics count: a joint one leg drives and the other follows (a hip both legs share)
    makes the legs alike, not one of them longer.
    """
    world = d.world
    if not (world.has_body(c.root) and world.has_body(c.tip)):
        return []
    try:
        conns = world.compute_chain_of_connections(c.root, c.tip)
    except RobotSpecError:
        return []
    return [j for j in conns if not j.is_fixed]


def find_questions(d: Drafter) -> list[DraftQuestion]:
    """Questions about what no drafted part covers (see the module docstring)."""
    return (
        _joint_questions(d)
        + _long_part_questions(d)
        + _uneven_limb_questions(d)
        + open_end_questions(d)
        + camera_questions(d)
    )


def asked(draft: Draft) -> tuple[frozenset[str], frozenset[str]]:
    """(joints, links) the draft's questions name: what the corpus measure counts as asked."""
    joints: set[str] = set()
    links: set[str] = set()
    for q in draft.questions:
        joints |= q.joints
        links |= q.links
    return frozenset(joints), frozenset(links)
