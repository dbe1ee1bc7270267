/* A supervisor written against the IDL alone, in plain C with Cyclone DDS:
 * it waits for one pump's state, commands its pump on for a few seconds,
 * and watches the echo. Build it from idl/dnbridge.idl with idlc, as
 * CMakeLists.txt beside it does. Usage: supervisor RACK PORT MAC [SECONDS]
 *
 * The QoS below is what the bridge's topics promise (README, "Data model"):
 * a reader of state that is reliable and transient-local with keep-last 1
 * gets the current state at once; a command writer must be reliable,
 * volatile, keep-last 1 with exclusive ownership (its strength decides who
 * commands a pump) and keeps the pump commanded only while it lives; its
 * liveliness lease (2 s here) is how long a frozen supervisor keeps the
 * pump, and the bridge refuses one over its max_commander_lease_ms (10 s
 * unless configured). When the node has a command refresh (NodeStatus
 * command_refresh_ms), the writer offers it as its deadline and writes at
 * a quarter of it. It is published in the rack's partition, "dnbridge/" followed by the rack name:
 * the bridge of that rack reads commands there, and no other bridge gets
 * them. State is in the default partition: one reader for every rack. */
#include <dds/dds.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dnbridge.h"

static dds_qos_t* state_reader_qos(void) {
  dds_qos_t* q = dds_create_qos();
  dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_MSECS(100));
  dds_qset_durability(q, DDS_DURABILITY_TRANSIENT_LOCAL);
  dds_qset_history(q, DDS_HISTORY_KEEP_LAST, 1);
  dds_qset_destination_order(q, DDS_DESTINATIONORDER_BY_SOURCE_TIMESTAMP);
  return q;
}

/* `refresh_ms`: the node's command refresh, 0 when it has none. */
static dds_qos_t* command_writer_qos(const char* rack, int32_t strength, uint32_t refresh_ms) {
  dds_qos_t* q = dds_create_qos();
  static char partition[256];
  if (snprintf(partition, sizeof partition, "dnbridge/%s", rack) >= (int)sizeof partition) {
    fprintf(stderr, "rack name too long\n");
    exit(2);
  }
  const char* partitions[] = {partition};
  dds_qset_partition(q, 1, partitions);
  dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_MSECS(100));
  dds_qset_durability(q, DDS_DURABILITY_VOLATILE);
  dds_qset_history(q, DDS_HISTORY_KEEP_LAST, 1);
  dds_qset_ownership(q, DDS_OWNERSHIP_EXCLUSIVE);
  dds_qset_ownership_strength(q, strength);
  dds_qset_liveliness(q, DDS_LIVELINESS_AUTOMATIC, DDS_SECS(2));
  dds_qset_destination_order(q, DDS_DESTINATIONORDER_BY_SOURCE_TIMESTAMP);
  dds_qset_writer_data_lifecycle(q, false);
  if (refresh_ms > 0) dds_qset_deadline(q, DDS_MSECS(refresh_ms));
  return q;
}

/* The node's command refresh as its NodeStatus says (transient-local: here
 * once matched), waiting at most `ms`; 0 when it has none or no NodeStatus
 * came. */
static uint32_t command_refresh_ms(dds_entity_t participant, const char* rack, const char* port,
                                   uint8_t mac, int ms) {
  dds_entity_t topic =
      dds_create_topic(participant, &dnbridge_NodeStatus_desc, "dnbridge/NodeStatus", NULL, NULL);
  dds_qos_t* rq = state_reader_qos();
  dds_entity_t reader = dds_create_reader(participant, topic, rq, NULL);
  dds_delete_qos(rq);
  dds_entity_t waitset = dds_create_waitset(participant);
  dds_entity_t readable = dds_create_readcondition(reader, DDS_ANY_STATE);
  dds_waitset_attach(waitset, readable, 0);
  const dds_time_t deadline = dds_time() + DDS_MSECS(ms);
  uint32_t refresh = 0;
  int found = 0;
  while (!found && dds_time() < deadline) {
    dds_waitset_wait_until(waitset, NULL, 0, deadline);
    void* samples[16] = {NULL};
    dds_sample_info_t infos[16];
    int n = dds_take(reader, samples, infos, 16, 16);
    for (int i = 0; i < n; i++) {
      const dnbridge_NodeStatus* s = samples[i];
      if (infos[i].valid_data && strcmp(s->rack, rack) == 0 && strcmp(s->port, port) == 0 &&
          s->mac == mac) {
        refresh = s->command_refresh_ms;
        found = 1;
      }
    }
    if (n > 0) dds_return_loan(reader, samples, n);
  }
  dds_delete(waitset);
  dds_delete(reader);
  return refresh;
}

typedef enum { ANY, ONLINE, COMMANDED, IDLE } Wanted;

/* Takes PumpState samples of (rack, port, mac) until one shows what is
 * wanted, for at most `ms`; prints each. Returns 1 if it came. */
static int wait_state(dds_entity_t waitset, dds_entity_t reader, const char* rack, const char* port,
                      uint8_t mac, Wanted wanted, int ms) {
  const dds_time_t deadline = dds_time() + DDS_MSECS(ms);
  while (dds_time() < deadline) {
    dds_waitset_wait_until(waitset, NULL, 0, deadline);
    void* samples[16] = {NULL};
    dds_sample_info_t infos[16];
    int n = dds_take(reader, samples, infos, 16, 16);
    int done = 0;
    for (int i = 0; i < n; i++) {
      const dnbridge_PumpState* s = samples[i];
      if (!infos[i].valid_data || strcmp(s->rack, rack) != 0 || strcmp(s->port, port) != 0 ||
          s->mac != mac) {
        continue;
      }
      printf(
          "  %s/%s/%u %s online=%d running=%d alarm=%d interlock_ok=%d pump_on=%d idle=%d by "
          "\"%s\"\n",
          s->rack, s->port, s->mac, s->name, s->online, s->pump_running, s->alarm_active,
          s->interlock_ok, s->pump_on, s->outputs_idle, s->commanded_by);
      done = done || wanted == ANY || (wanted == ONLINE && s->online) ||
             (wanted == COMMANDED && s->online && !s->outputs_idle && s->pump_on) ||
             (wanted == IDLE && s->outputs_idle);
    }
    if (n > 0) dds_return_loan(reader, samples, n);
    if (done) return 1;
  }
  return 0;
}

int main(int argc, char** argv) {
  if (argc < 4) {
    fprintf(stderr, "usage: %s RACK PORT MAC [SECONDS]\n", argv[0]);
    return 2;
  }
  const char* rack = argv[1];
  const char* port = argv[2];
  const uint8_t mac = (uint8_t)atoi(argv[3]);
  const int seconds = argc > 4 ? atoi(argv[4]) : 3;

  dds_entity_t participant = dds_create_participant(DDS_DOMAIN_DEFAULT, NULL, NULL);
  if (participant < 0) {
    fprintf(stderr, "cannot create a participant: %s\n", dds_strretcode(participant));
    return 1;
  }
  dds_entity_t state_topic =
      dds_create_topic(participant, &dnbridge_PumpState_desc, "dnbridge/PumpState", NULL, NULL);
  dds_entity_t command_topic =
      dds_create_topic(participant, &dnbridge_PumpCommand_desc, "dnbridge/PumpCommand", NULL, NULL);
  dds_qos_t* rq = state_reader_qos();
  dds_entity_t reader = dds_create_reader(participant, state_topic, rq, NULL);
  dds_delete_qos(rq);
  const uint32_t refresh = command_refresh_ms(participant, rack, port, mac, 10000);
  /* Twice a second, or four times per command refresh. */
  const int period_ms = refresh > 0 && refresh / 4 < 500 ? (int)(refresh / 4) : 500;
  if (refresh > 0) printf("the node's command refresh: %u ms\n", refresh);
  dds_qos_t* wq = command_writer_qos(rack, 10, refresh);
  dds_entity_t writer = dds_create_writer(participant, command_topic, wq, NULL);
  dds_delete_qos(wq);

  dds_entity_t waitset = dds_create_waitset(participant);
  dds_entity_t readable = dds_create_readcondition(reader, DDS_ANY_STATE);
  dds_waitset_attach(waitset, readable, 0);

  printf("waiting for the pump to be online:\n");
  if (!wait_state(waitset, reader, rack, port, mac, ONLINE, 10000)) {
    fprintf(stderr, "%s/%s/%u is not online: is the bridge running on this domain?\n", rack, port,
            mac);
    dds_delete(participant);
    return 3;
  }

  dnbridge_PumpCommand command = {0};
  command.rack = (char*)rack;
  command.port = (char*)port;
  command.mac = mac;
  command.pump_on = true;
  command.issuer = "supervisor example";
  printf("commanding the pump on for %d s:\n", seconds);
  int applied = 0;
  for (int i = 0; i < seconds * 1000 / period_ms; i++) {
    /* Written again periodically: a commander that writes periodically takes
     * over at once when a stronger one goes away, its first write cannot be
     * lost to a bridge that has not matched it yet, and a node's command
     * refresh stays met. */
    dds_write(writer, &command);
    applied |= wait_state(waitset, reader, rack, port, mac, COMMANDED, period_ms);
  }
  if (!applied) {
    fprintf(stderr, "the command was not applied\n");
    dds_delete(participant);
    return 1;
  }
  printf("leaving: with no commander left the bridge idles the pump\n");
  dds_delete(writer);
  const int idle = wait_state(waitset, reader, rack, port, mac, IDLE, 5000);
  if (!idle) fprintf(stderr, "the pump did not go idle\n");
  dds_delete(participant);
  return idle ? 0 : 1;
}
