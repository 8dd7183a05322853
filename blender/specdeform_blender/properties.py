"""Per object settings, `obj.specdeform`, with the command line's defaults."""

import bpy
from bpy.props import (
    BoolProperty,
    CollectionProperty,
    EnumProperty,
    FloatProperty,
    FloatVectorProperty,
    IntProperty,
    PointerProperty,
    StringProperty,
)


def _bound_matrix():
    return FloatVectorProperty(
        name="Object in target",
        size=16,
        description="The object's matrix in its target's space when bound",
    )


def _retag(self, _context):
    """Enabled or Strength changed: the depsgraph handler writes the mesh again."""
    self.id_data.update_tag()


class SpecdeformHandle(bpy.types.PropertyGroup):
    """A further handle: a vertex group and the object that moves it."""

    group: StringProperty(name="Group", description="Vertex group moved by the target")
    target: PointerProperty(
        name="Target",
        type=bpy.types.Object,
        description="Object (normally an Empty) whose transform since binding moves the group",
    )
    bound_matrix: _bound_matrix()


class SpecdeformSettings(bpy.types.PropertyGroup):
    # The first handle (handle_group, target) and any further ones (handles): each is a handle
    # group of the library's scene, its vertex weights blending rest and target as a Hook does.
    handle_group: StringProperty(
        name="Handle", description="Vertex group moved by the target"
    )
    target: PointerProperty(
        name="Target",
        type=bpy.types.Object,
        description="Object (normally an Empty) whose transform since binding moves the handle",
    )
    bound_matrix: _bound_matrix()
    handles: CollectionProperty(type=SpecdeformHandle, name="More handles")
    handle_index: IntProperty(name="Active handle", default=0)
    fixed_group: StringProperty(
        name="Fixed", description="Vertex group that stays in place (optional)"
    )
    modes: IntProperty(
        name="Modes",
        description="Manifold harmonics the deformation uses",
        default=100,
        min=1,
        max=5000,
    )
    eigensolver: EnumProperty(
        name="Basis",
        description="How the harmonics are computed",
        items=(
            ("auto", "Automatic", "Exact below 200,000 vertices, multilevel from there"),
            ("krylov", "Exact", "The exact harmonics (slow on very large meshes)"),
            ("multilevel", "Multilevel", "An approximation for large meshes, several times faster"),
        ),
        default="auto",
    )
    energy: EnumProperty(
        name="Energy",
        items=(
            ("arap", "ARAP", "As-rigid-as-possible in the spectral space: rings stay round"),
            ("linear", "Linear", "The paper's linear thin-shell energy (one solve, no rotation)"),
        ),
        default="arap",
    )
    detail: EnumProperty(
        name="Detail",
        items=(
            ("transfer", "Transfer", "Deformation transfer of the details (rotates them)"),
            ("displacement", "Displacement", "Details added back unrotated"),
            ("frames", "Frames", "Details in local frames (the paper's section 4.4)"),
            ("none", "None", "The smooth base only"),
        ),
        default="transfer",
    )
    unconstrained: EnumProperty(
        name="Loose parts",
        description="Loose parts without a handle or fixed vertex",
        items=(
            ("follow", "Follow", "Move rigidly with the deformed surface around them"),
            ("keep", "Keep", "Stay where they are"),
        ),
        default="follow",
    )
    constraint_weight: FloatProperty(
        name="Constraint weight",
        description="How firmly the handles reach their targets and the fixed vertices stay: "
        "soft constraints, weighed against the surface's energy on the mesh scaled to unit area "
        "(higher: closer; the default holds them to about 1e-5 of the mesh's size)",
        default=1e5,
        min=1e-6,
    )
    quick_drags: BoolProperty(
        name="Quick drags",
        description="Where a full update takes over 50 ms: while a target moves, the details are "
        "added as displacements, and the full details follow once it rests for a quarter second "
        "(renders and bakes always have them)",
        default=True,
    )
    enabled: BoolProperty(
        name="Enabled",
        description="Show the pose (off: the rest shape), in the viewport and in renders, as a "
        "modifier's toggles",
        default=True,
        update=_retag,
    )
    strength: FloatProperty(
        name="Strength",
        description="How much of the pose is shown: rest + strength x (pose - rest); keyframable",
        default=1.0,
        min=0.0,
        max=1.0,
        subtype="FACTOR",
        update=_retag,
    )
    bound: BoolProperty(name="Bound", description="The mesh follows the target", default=False)
    saved_full: BoolProperty(
        name="Saved in full",
        description="The pose saved in the file carries the full details (not displacements)",
        default=True,
    )
