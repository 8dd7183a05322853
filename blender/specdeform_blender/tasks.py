"""Binds that leave the window free: Bind from the panel, the bound meshes of a reopened file and
a mesh leaving Edit Mode each run as a Task, the main thread's steps of preparing.steps() driven
by a timer (one step of each task every TICK_S; the window handles its events in between), their
progress in the sidebar's panel, the objects being bound named in the status bar. Esc cancels
every running task at once: a watcher (a modal operator that lets every other event through)
reads it. A render waits for the tasks (render_init); without a window (`blender -b`) a bind
runs at once."""

import time

import bpy

from . import preparing

TICK_S = 0.02  # between two rounds of the tasks' steps

_tasks = {}  # Object.name_full -> Task
_watchers = 0  # modal operators reading Esc


class Task:
    """One object's bind in steps; done(obj, error) is called once, on the main thread, when it
    ends (error None when bound, preparing.CANCELLED when cancelled). `showing`: what the mesh
    shows meanwhile, in the panel's words."""

    def __init__(self, obj, done, keep_shown, showing):
        self.name, self.done, self.showing = obj.name_full, done, showing
        self.bound = obj.specdeform.bound  # binding again (not a first Bind)
        self.started = time.perf_counter()
        self.finished, self.error = False, None
        self._pipeline = preparing.steps(obj, keep_shown)
        self._waiting = ("starting", 0.0)
        self._advance(lambda: next(self._pipeline))

    def _advance(self, resume):
        try:
            self._waiting = resume()
        except StopIteration as end:
            self._end(end.value)
        except Exception as e:  # a bpy or library error in a step: said, never left running
            self._pipeline.close()
            self._end(f"bind: {e}")

    def step(self):
        """The next main-thread step, unless the worker is still busy."""
        if self.finished:
            return
        obj = bpy.data.objects.get(self.name)
        if obj is None:
            return self.cancel("bind: the object was renamed or deleted while it was being bound")
        if isinstance(self._waiting, preparing.BindJob) and not self._waiting.done:
            return
        self._advance(lambda: self._pipeline.send(obj))

    def run_now(self):
        """The remaining steps at once (a render waits for the pose)."""
        while not self.finished:
            if isinstance(self._waiting, preparing.BindJob):
                self._waiting.join(0.1)
            self.step()

    def cancel(self, why=preparing.CANCELLED):
        """Ends the task at once; the worker stops at its next report (its result dropped)."""
        if not self.finished:
            self._pipeline.close()
            self._end(why)

    def text(self):
        """'Binding: <stage> 40% · 12 s' (the seconds since it began)."""
        w = self._waiting
        line = w.progress_text() if isinstance(w, preparing.BindJob) else f"{w[0]} {w[1]:.0%}"
        return f"Binding: {line} · {time.perf_counter() - self.started:.0f} s"

    def _end(self, error):
        self.finished, self.error = True, error
        if _tasks.get(self.name) is self:
            del _tasks[self.name]
        self.done(bpy.data.objects.get(self.name), error)


def in_window():
    """Whether binds run as tasks: Blender has a window (tests drive the tasks headless)."""
    return not bpy.app.background


def start(obj, done, keep_shown=False, showing="the mesh stays as it is"):
    """Binds `obj` as a task (in a window) or at once (`blender -b`: done is called before this
    returns); keep_shown: see binding.attach; showing: see Task. Returns the task, or None."""
    if not in_window():
        report = lambda text: print(f"specdeform: '{obj.name}': {text}")  # noqa: E731
        done(obj, preparing.bind_now(obj, report, keep_shown))
        return None
    cancel(obj)
    task = Task(obj, done, keep_shown, showing)
    if not task.finished:
        _tasks[task.name] = task
        if not bpy.app.timers.is_registered(_tick):
            bpy.app.timers.register(_tick, first_interval=TICK_S)
    return task


def running(obj):
    return _tasks.get(obj.name_full)


def cancel(obj, why=preparing.CANCELLED):
    task = _tasks.get(obj.name_full)
    if task is not None:
        task.cancel(why)


def cancel_all(why=preparing.CANCELLED):
    for task in list(_tasks.values()):
        task.cancel(why)


def all_running():
    return list(_tasks.values())


def finish(obj):
    """The object's bind finished now, where one runs (Apply)."""
    task = _tasks.get(obj.name_full)
    if task is not None:
        task.run_now()


@bpy.app.handlers.persistent
def finish_all(*_):
    """render_init: a render shows the poses, so the binds still running finish first."""
    for task in list(_tasks.values()):
        task.run_now()


def shutdown():
    """The add-on disabled: the tasks cancelled and their timer stopped."""
    cancel_all()
    if bpy.app.timers.is_registered(_tick):
        bpy.app.timers.unregister(_tick)


def status_line():
    """The status bar's line while binds run: which objects (the progress is in the sidebar: a
    status bar that changes redraws the whole window, a quarter of a second in software GL)."""
    names = ", ".join(f"'{name}'" for name in _tasks)
    return f"{names}, progress in the sidebar (N) (Esc cancels)"


def _tick():
    for task in list(_tasks.values()):
        task.step()
    wm = bpy.context.window_manager
    for window in wm.windows if wm else ():
        for area in window.screen.areas:  # the sidebars and the status bar: a viewport's
            for region in area.regions:  # redraw of a large mesh takes seconds in software GL
                if (area.type, region.type) in (("VIEW_3D", "UI"), ("STATUSBAR", "WINDOW")):
                    region.tag_redraw()
        if _tasks and _watchers == 0 and not bpy.app.background:
            with bpy.context.temp_override(window=window):
                bpy.ops.specdeform.watch("INVOKE_DEFAULT")
    return TICK_S if _tasks else None


class Watcher:
    """A modal operator's part that reads Esc (cancelling every task) and names the objects being
    bound in the status bar, letting every other event through, until ended() says so."""

    def watch(self, context):
        global _watchers
        _watchers += 1
        wm = context.window_manager
        self._timer = wm.event_timer_add(0.1, window=context.window)
        self._status = None
        wm.modal_handler_add(self)
        return {"RUNNING_MODAL"}

    def modal(self, context, event):
        if event.type == "ESC" and event.value == "PRESS" and _tasks:
            cancel_all()
            return self._stop(context) if self.ended() else {"RUNNING_MODAL"}
        if event.type == "TIMER" and _tasks and status_line() != self._status:
            self._status = status_line()
            context.workspace.status_text_set(f"specdeform: binding {self._status}")
        return self._stop(context) if self.ended() else {"PASS_THROUGH"}

    def cancel(self, context):  # a file loaded, Blender quitting
        self._stop(context)

    def _stop(self, context):
        global _watchers
        _watchers -= 1
        context.window_manager.event_timer_remove(self._timer)
        if not _tasks:
            context.workspace.status_text_set(None)
        return self.end()


class SPECDEFORM_OT_watch(Watcher, bpy.types.Operator):
    """Binds running in the background (a reopened file, Edit Mode left): Esc cancels them"""

    bl_idname = "specdeform.watch"
    bl_label = "specdeform: binding"
    bl_options = {"INTERNAL"}

    def invoke(self, context, _event):
        return self.watch(context)

    def ended(self):
        return not _tasks

    def end(self):
        return {"FINISHED"}
