// `avs bag play --view` (issue 17): a bag recorded from view_test_publisher is played with the
// live view in the player's process; the Foxglove client lists the bag's channels, and the
// poses and depth images it decodes with the advertised schemas hold the values
// view_test_publisher wrote (functions of the message index), so the recorded CDR went
// through player and server unchanged. Waits are for conditions, never for speed.
// usage: node check_bag_view.mjs ws://127.0.0.1:PORT
import { check, checkImage, checkPose, tally, Viewer, waitFor } from "./view_client.mjs";

const [url] = process.argv.slice(2);

async function main() {
  const v = new Viewer(url, "bag");
  await waitFor("channels /object/pose and /depth/image", () =>
    v.channel("/object/pose") && v.channel("/depth/image"));
  check(v.channel("/object/pose").schemaName === "geometry_msgs/msg/PoseStamped", "pose type");
  check(v.channel("/depth/image").schemaName === "sensor_msgs/msg/Image", "image type");
  v.subscribe("/object/pose");
  v.subscribe("/depth/image");
  await waitFor("20 poses and 3 images", () => v.count("/object/pose") >= 20 && v.count("/depth/image") >= 3);
  check(v.received.get("/object/pose").every(checkPose), "every played pose as recorded");
  check(v.received.get("/depth/image").every(checkImage), "every played image as recorded");
  console.log(`decoded ${v.count("/object/pose")} poses and ${v.count("/depth/image")} images from the bag`);
  v.client.close();
  console.log(tally.failures === 0 ? "bag view check: all passed" : `bag view check: ${tally.failures} failures`);
  process.exit(tally.failures === 0 ? 0 : 1);
}

main().catch((e) => {
  console.error(`FAILED: ${e.message}`);
  process.exit(1);
});
