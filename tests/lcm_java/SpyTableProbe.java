// A Java agent that reads lcm-spy's channel table as a person sees it, for the lcm-spy test. Loaded
// into the lcm-spy process (JAVA_TOOL_OPTIONS=-javaagent:lcm-java-checks.jar=OUT), it changes nothing
// there: every 200 ms it finds the "LCM Spy" window, reads its table's columns Channel, Type,
// Num Msgs and Undecodable on the Swing thread, and writes them, one tab-separated line per row
// after a header line, to OUT (through OUT.tmp and a rename, so a reader never sees half a table).
// lcm-spy shows a type's class name when it knows the type, "?? <fingerprint>" when it does not.
import java.awt.Component;
import java.awt.Container;
import java.awt.Frame;
import java.io.IOException;
import java.lang.instrument.Instrumentation;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.nio.file.Paths;
import java.nio.file.StandardCopyOption;
import javax.swing.JTable;
import javax.swing.SwingUtilities;
import javax.swing.table.TableModel;

public final class SpyTableProbe {
  private static final String[] COLUMNS = {"Channel", "Type", "Num Msgs", "Undecodable"};

  public static void premain(String args, Instrumentation instrumentation) {
    final Path out = Paths.get(args);
    final Thread thread = new Thread(() -> watch(out), "spy-table-probe");
    thread.setDaemon(true);
    thread.start();
  }

  private static void watch(Path out) {
    final Path partial = Paths.get(out + ".tmp");
    while (true) {
      try {
        Thread.sleep(200);
        final String[] table = new String[1];
        SwingUtilities.invokeAndWait(() -> table[0] = readTable());
        if (table[0] == null) continue;
        Files.write(partial, table[0].getBytes(StandardCharsets.UTF_8));
        Files.move(partial, out, StandardCopyOption.REPLACE_EXISTING, StandardCopyOption.ATOMIC_MOVE);
      } catch (InterruptedException e) {
        return;
      } catch (IOException | java.lang.reflect.InvocationTargetException e) {
        System.err.println("SpyTableProbe: " + e);
      }
    }
  }

  private static JTable findTable(Component c) {
    if (c instanceof JTable) return (JTable) c;
    if (c instanceof Container)
      for (Component child : ((Container) c).getComponents()) {
        final JTable t = findTable(child);
        if (t != null) return t;
      }
    return null;
  }

  // The table of the visible "LCM Spy" window, or null before there is one.
  private static String readTable() {
    for (Frame frame : Frame.getFrames()) {
      if (!frame.isVisible() || !"LCM Spy".equals(frame.getTitle())) continue;
      final JTable table = findTable(frame);
      if (table == null) return null;
      final TableModel model = table.getModel();
      final int[] index = new int[COLUMNS.length];
      final StringBuilder text = new StringBuilder(String.join("\t", COLUMNS)).append('\n');
      for (int i = 0; i < COLUMNS.length; ++i) {
        index[i] = -1;
        for (int c = 0; c < model.getColumnCount(); ++c)
          if (COLUMNS[i].equals(model.getColumnName(c))) index[i] = c;
        if (index[i] < 0) return "no column " + COLUMNS[i] + "\n";
      }
      for (int r = 0; r < model.getRowCount(); ++r) {
        for (int i = 0; i < index.length; ++i)
          text.append(i > 0 ? "\t" : "").append(String.valueOf(model.getValueAt(r, index[i])).trim());
        text.append('\n');
      }
      return text.toString();
    }
    return null;
  }
}
