// Undo / redo over whole editor states: `current()` is the state after the last push, undo and
// redo move through the pushed states and report whether they moved.
export class History<T> {
  private states: T[] = [];
  private index = -1;

  reset(initial: T): void {
    this.states = [initial];
    this.index = 0;
  }

  push(state: T): void {
    this.states = this.states.slice(0, this.index + 1);
    this.states.push(state);
    this.index = this.states.length - 1;
  }

  current(): T {
    return this.states[this.index];
  }

  undo(): boolean {
    if (this.index <= 0) return false;
    --this.index;
    return true;
  }

  redo(): boolean {
    if (this.index >= this.states.length - 1) return false;
    ++this.index;
    return true;
  }
}
