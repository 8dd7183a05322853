// The WebSocket to `specdeform edit`: typed messages in and out, and reconnection with backoff
// (0.5 s doubling to 8 s) after the server went away. A window that another one took over does
// not reconnect by itself (the two would take turns); it offers to.
import * as P from './protocol';

export type ConnectionStatus =
  | { kind: 'connecting'; attempt: number }
  | { kind: 'open' }
  | { kind: 'closed'; reason: string; retryAt: number | null }; // retryAt: performance.now() ms

export interface ConnectionEvents {
  status(status: ConnectionStatus): void;
  text(message: P.ServerText): void;
  binary(buffer: ArrayBuffer): void;
}

const TAKEN_OVER = 'another editor window connected';

export class Connection {
  private socket: WebSocket | null = null;
  private attempt = 0;
  private retryTimer: number | undefined;
  status: ConnectionStatus = { kind: 'connecting', attempt: 0 };

  // The events go to `on`, set by whoever reads them (the socket may be opened first: nothing
  // arrives before the task that opens it ends).
  on: ConnectionEvents = { status: () => {}, text: () => {}, binary: () => {} };

  constructor(private readonly url: string) {}

  get open(): boolean {
    return this.status.kind === 'open';
  }

  connect(): void {
    clearTimeout(this.retryTimer);
    this.socket?.close();
    const socket = new WebSocket(this.url);
    this.socket = socket;
    socket.binaryType = 'arraybuffer';
    this.setStatus({ kind: 'connecting', attempt: this.attempt });
    socket.onopen = () => {
      this.attempt = 0;
      this.setStatus({ kind: 'open' });
    };
    socket.onmessage = (e) => {
      if (typeof e.data === 'string') this.on.text(JSON.parse(e.data) as P.ServerText);
      else this.on.binary(e.data as ArrayBuffer);
    };
    socket.onclose = (e) => {
      if (socket !== this.socket) return;
      this.socket = null;
      if (e.reason === TAKEN_OVER) {
        return this.setStatus({ kind: 'closed', reason: 'this editor was opened in another window', retryAt: null });
      }
      const reason = e.code === 1009
        ? 'the file is larger than the server accepts (specdeform edit --max-upload-mb)'
        : e.reason || (this.attempt > 0 ? 'the server does not answer' : 'the connection to the server was lost');
      const delay = Math.min(8000, 500 * 2 ** this.attempt++);
      this.retryTimer = window.setTimeout(() => this.connect(), delay);
      this.setStatus({ kind: 'closed', reason, retryAt: performance.now() + delay });
    };
  }

  // Drops a message when not connected: the caller checks `open` where that matters.
  send(message: P.ClientText | ArrayBuffer): boolean {
    if (!this.socket || this.socket.readyState !== WebSocket.OPEN) return false;
    this.socket.send(message instanceof ArrayBuffer ? message : JSON.stringify(message));
    return true;
  }

  private setStatus(status: ConnectionStatus): void {
    this.status = status;
    this.on.status(status);
  }
}
