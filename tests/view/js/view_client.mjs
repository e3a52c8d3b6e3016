// What the `avs view` checks share (check_view.mjs, check_bag_view.mjs): the official
// Foxglove WebSocket client (@foxglove/ws-protocol) keeping the channel list and decoding
// each message with its advertised ros2msg schema (@foxglove/rosmsg +
// @foxglove/rosmsg2-serialization), condition waits, and the checks of view_test_publisher's
// values (functions of the message index).
import { createRequire } from "node:module";

const require = createRequire(import.meta.url);
const { FoxgloveClient } = require("@foxglove/ws-protocol");
const { parse } = require("@foxglove/rosmsg");
const { MessageReader } = require("@foxglove/rosmsg2-serialization");
export const WebSocket = require("ws");
export { FoxgloveClient };

const TIMEOUT_MS = 60000;
export const tally = { failures: 0 };
export const check = (ok, what) => {
  if (!ok) {
    tally.failures++;
    console.error(`FAILED: ${what}`);
  }
  return ok;
};

export function waitFor(what, condition, timeoutMs = TIMEOUT_MS) {
  return new Promise((resolve, reject) => {
    const start = Date.now();
    const poll = () => {
      let value;
      try {
        value = condition();
      } catch (e) {
        reject(e);
        return;
      }
      if (value) resolve(value);
      else if (Date.now() - start > timeoutMs) reject(new Error(`timed out waiting for ${what}`));
      else setTimeout(poll, 20);
    };
    poll();
  });
}

/// A Foxglove client that keeps the channel list and decodes what it receives.
export class Viewer {
  constructor(url, name, query = "") {
    this.name = name;
    this.channels = new Map(); // id -> channel
    this.readers = new Map(); // channel id -> MessageReader
    this.subscriptions = new Map(); // subscription id -> channel id
    this.received = new Map(); // topic -> array of decoded messages
    this.statuses = [];
    this.unadvertised = [];
    this.serverInfo = undefined;
    this.ws = new WebSocket(url + query, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]);
    this.client = new FoxgloveClient({ ws: this.ws });
    this.client.on("serverInfo", (info) => (this.serverInfo = info));
    this.client.on("status", (s) => this.statuses.push(s));
    this.client.on("advertise", (channels) => {
      for (const c of channels) this.channels.set(c.id, c);
    });
    this.client.on("unadvertise", (ids) => {
      for (const id of ids) {
        this.channels.delete(id);
        this.unadvertised.push(id);
      }
    });
    this.client.on("message", ({ subscriptionId, data }) => {
      const channelId = this.subscriptions.get(subscriptionId);
      if (channelId === undefined) return; // unsubscribed meanwhile
      const channel = this.channels.get(channelId);
      const bytes = new Uint8Array(data.buffer, data.byteOffset, data.byteLength);
      const message = this.readers.get(channelId).readMessage(bytes);
      if (!this.received.has(channel.topic)) this.received.set(channel.topic, []);
      this.received.get(channel.topic).push(message);
    });
    this.client.on("error", (e) => console.error(`${name}: client error: ${e}`));
  }
  channel(topic) {
    for (const c of this.channels.values()) if (c.topic === topic) return c;
    return undefined;
  }
  count(topic) {
    return (this.received.get(topic) ?? []).length;
  }
  subscribe(topic) {
    const c = this.channel(topic);
    this.readers.set(c.id, new MessageReader(parse(c.schema, { ros2: true })));
    const id = this.client.subscribe(c.id);
    this.subscriptions.set(id, c.id);
    return id;
  }
  unsubscribe(subscriptionId) {
    this.client.unsubscribe(subscriptionId);
    this.subscriptions.delete(subscriptionId);
  }
}

export function checkPose(m) {
  const i = m.header.stamp.sec - 100;
  return (
    check(m.header.frame_id === "camera_optical_frame", `pose frame_id ${m.header.frame_id}`) &&
    check(m.pose.position.x === i * 0.001, `pose ${i} x ${m.pose.position.x}`) &&
    check(m.pose.position.y === -(i * 0.5), `pose ${i} y ${m.pose.position.y}`) &&
    check(m.pose.position.z === 1.25, `pose ${i} z`) &&
    check(
      m.pose.orientation.x === 0 && m.pose.orientation.y === 0 &&
        m.pose.orientation.z === 0.6 && m.pose.orientation.w === 0.8,
      `pose ${i} orientation ${JSON.stringify(m.pose.orientation)}`,
    )
  );
}

export function checkImage(m) {
  const i = m.header.stamp.sec - 100;
  if (
    !check(m.header.frame_id === "camera_optical_frame", `image frame_id`) ||
    !check(m.encoding === "32FC1" && m.width === 160 && m.height === 120 && m.step === 640,
      `image ${i} header ${m.encoding} ${m.width}x${m.height} step ${m.step}`) ||
    !check(m.data.length === 160 * 120 * 4, `image ${i} data length ${m.data.length}`)
  ) {
    return false;
  }
  const view = new DataView(m.data.buffer, m.data.byteOffset, m.data.byteLength);
  for (let y = 0; y < 120; y++) {
    for (let x = 0; x < 160; x++) {
      const expected = Math.fround(Math.fround(i % 1000) + x * 0.5 + y * 0.25);
      const got = view.getFloat32((y * 160 + x) * 4, true);
      if (!check(got === expected, `image ${i} pixel (${x}, ${y}) = ${got}, expected ${expected}`)) {
        return false;
      }
    }
  }
  return true;
}

