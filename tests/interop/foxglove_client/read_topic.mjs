// Reads one message of a topic from a Foxglove WebSocket server with Foxglove's own client
// (@foxglove/ws-protocol, MIT), as Foxglove and Lichtblick connect: prints the server's
// name, the topics advertised and the first message of the topic asked for, as JSON.
//   node read_topic.mjs URL TOPIC
import protocol from "@foxglove/ws-protocol";
import WebSocket from "ws";

const { FoxgloveClient } = protocol;

const [url, topic] = process.argv.slice(2);
const client = new FoxgloveClient({
  ws: new WebSocket(url, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]),
});
const seen = { server: null, topics: [], message: null };
const done = (code) => {
  console.log(JSON.stringify(seen));
  client.close();
  process.exit(code);
};
setTimeout(() => done(2), 30000);
client.on("error", (error) => {
  seen.error = String(error?.message ?? error);
  done(3);
});
client.on("serverInfo", (info) => (seen.server = info.name));
const subscriptions = new Map();
client.on("advertise", (channels) => {
  for (const channel of channels) {
    seen.topics.push(channel.topic);
    if (channel.topic === topic) subscriptions.set(client.subscribe(channel.id), channel);
  }
});
client.on("message", ({ subscriptionId, data }) => {
  if (!subscriptions.has(subscriptionId)) return;
  seen.message = JSON.parse(new TextDecoder().decode(data));
  done(0);
});
