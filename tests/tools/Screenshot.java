// java tests/tools/Screenshot.java OUT.png: saves the whole X display ($DISPLAY) as a PNG and prints
// "WIDTHxHEIGHT COLOURS" (the number of distinct colours: a blank screen has 1). Run as a single
// source file (Java 11+); used by tests/replay_gui_test.sh under Xvfb.
import java.awt.Rectangle;
import java.awt.Robot;
import java.awt.Toolkit;
import java.awt.image.BufferedImage;
import java.io.File;
import java.util.HashSet;
import java.util.Set;
import javax.imageio.ImageIO;

public class Screenshot {
  public static void main(String[] args) throws Exception {
    if (args.length != 1) {
      System.err.println("usage: java Screenshot.java OUT.png");
      System.exit(2);
    }
    Rectangle screen = new Rectangle(Toolkit.getDefaultToolkit().getScreenSize());
    BufferedImage image = new Robot().createScreenCapture(screen);
    ImageIO.write(image, "png", new File(args[0]));
    Set<Integer> colours = new HashSet<>();
    for (int y = 0; y < image.getHeight(); y += 2) {
      for (int x = 0; x < image.getWidth(); x += 2) colours.add(image.getRGB(x, y));
    }
    System.out.println(image.getWidth() + "x" + image.getHeight() + " " + colours.size());
  }
}
