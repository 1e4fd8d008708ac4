// Counts every channel of an LCM log as a Java user of our types reads it: LCM's own log reader
// (lcm.logging.Log), the exlcm classes found in a jar the way lcm-spy finds types
// (lcm.util.ClassDiscoverer), each event decoded by its class's byte[] constructor (which checks the
// fingerprint). Prints one tab-separated line per channel, in name order:
//   channel type events undecodable first_seq last_seq seq_gaps first_utime last_utime
// A channel's type is that of its first decodable event; a later event that its class does not
// decode counts as undecodable. seq_gaps: decoded events whose seq is not the previous one's + 1.
// Usage: java -cp lcm.jar:exlcm.jar:lcm-java-checks.jar LogChannelCount EXLCM_JAR LOG
import java.io.EOFException;
import java.io.IOException;
import java.lang.reflect.Constructor;
import java.util.HashMap;
import java.util.Map;
import java.util.TreeMap;

import lcm.lcm.LCMEncodable;
import lcm.logging.Log;
import lcm.util.ClassDiscoverer;

public final class LogChannelCount {
  private static final class Channel {
    Constructor<?> type;
    long events, undecodable, seqGaps;
    long firstSeq = -1, lastSeq = -1, firstUtime = -1, lastUtime = -1;
  }

  private static long fingerprintOf(byte[] data) {
    long v = 0;
    for (int i = 0; i < 8 && i < data.length; ++i) v = v << 8 | (data[i] & 0xff);
    return v;
  }

  public static void main(String[] args) throws IOException {
    if (args.length != 2) {
      System.err.println("usage: LogChannelCount EXLCM_JAR LOG");
      System.exit(2);
    }
    final Map<Long, Constructor<?>> types = new HashMap<>();
    ClassDiscoverer.findClasses(args[0], (jar, cls) -> {
      if (!LCMEncodable.class.isAssignableFrom(cls)) return;
      try {
        types.put(cls.getField("LCM_FINGERPRINT").getLong(null), cls.getConstructor(byte[].class));
      } catch (ReflectiveOperationException e) {
        System.err.println("LogChannelCount: " + cls.getName() + ": " + e);
      }
    });
    if (types.isEmpty()) {
      System.err.println("LogChannelCount: no LCM types in " + args[0]);
      System.exit(1);
    }
    final Map<String, Channel> channels = new TreeMap<>();
    final Log log = new Log(args[1], "r");
    while (true) {
      final Log.Event event;
      try {
        event = log.readNext();
      } catch (EOFException end) {
        break;
      }
      final Channel c = channels.computeIfAbsent(event.channel, k -> new Channel());
      ++c.events;
      final Constructor<?> type = types.get(fingerprintOf(event.data));
      if (c.type == null) c.type = type;
      if (type == null || type != c.type) {
        ++c.undecodable;
        continue;
      }
      final long seq, utime;
      try {
        final Object message = type.newInstance((Object) event.data);
        seq = message.getClass().getField("seq").getLong(message);
        utime = message.getClass().getField("utime").getLong(message);
      } catch (ReflectiveOperationException e) {
        ++c.undecodable;
        continue;
      }
      if (c.firstSeq < 0) {
        c.firstSeq = seq;
        c.firstUtime = utime;
      } else if (seq != c.lastSeq + 1) {
        ++c.seqGaps;
      }
      c.lastSeq = seq;
      c.lastUtime = utime;
    }
    log.close();
    for (Map.Entry<String, Channel> e : channels.entrySet()) {
      final Channel c = e.getValue();
      final String type = c.type == null ? "unknown" : c.type.getDeclaringClass().getSimpleName();
      System.out.println(e.getKey() + "\t" + type + "\t" + c.events + "\t" + c.undecodable + "\t" + c.firstSeq + "\t"
                         + c.lastSeq + "\t" + c.seqGaps + "\t" + c.firstUtime + "\t" + c.lastUtime);
    }
  }
}
