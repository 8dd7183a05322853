"""Per object settings, `obj.specdeform`, with the command line's defaults."""

import bpy
from bpy.props import (
    BoolProperty,
    EnumProperty,
    FloatProperty,
    FloatVectorProperty,
    IntProperty,
    PointerProperty,
    StringProperty,
)


class SpecdeformSettings(bpy.types.PropertyGroup):
    # One handle group and its target now; several, each with its own target, will be a
    # collection of (group, target) pairs: the binding already keeps lists of both.
    handle_group: StringProperty(
        name="Handle", description="Vertex group moved by the target"
    )
    fixed_group: StringProperty(
        name="Fixed", description="Vertex group that stays in place (optional)"
    )
    target: PointerProperty(
        name="Target",
        type=bpy.types.Object,
        description="Object (normally an Empty) whose transform since binding moves the handle",
    )
    modes: IntProperty(
        name="Modes",
        description="Manifold harmonics the deformation uses",
        default=100,
        min=1,
        max=5000,
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
        name="Free pieces",
        description="Loose parts without a handle or fixed vertex",
        items=(
            ("follow", "Follow", "Move rigidly with the deformed surface around them"),
            ("keep", "Keep", "Stay where they are"),
        ),
        default="follow",
    )
    constraint_weight: FloatProperty(
        name="Weight",
        description="Soft constraint weight (on the mesh scaled to unit area)",
        default=1e5,
        min=1e-6,
    )
    bound: BoolProperty(name="Bound", description="The mesh follows the target", default=False)
    bound_matrix: FloatVectorProperty(
        name="Object in target",
        size=16,
        description="The object's matrix in its target's space when bound",
    )
